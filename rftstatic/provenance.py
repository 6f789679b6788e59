"""Where a result comes from: the package version, the git commit, a fingerprint of the code, peak memory.

``summary.json`` records :func:`software` and :func:`peak_memory_mb`; every cache of solved runs keys
on :func:`code_fingerprint`, so that a result computed by other code is never reused.
"""

from __future__ import annotations

import functools
import hashlib
import platform
import resource
import subprocess
import sys
from pathlib import Path

__version__ = "0.1.0"

PACKAGE_DIR = Path(__file__).resolve().parent


@functools.lru_cache(maxsize=1)
def code_fingerprint() -> str:
    """SHA-1 [hex] of the package's Python sources (paths and contents, sorted): changes with any edit."""
    h = hashlib.sha1()
    for path in sorted(PACKAGE_DIR.rglob("*.py")):
        if "__pycache__" in path.parts:
            continue
        h.update(str(path.relative_to(PACKAGE_DIR)).encode())
        h.update(b"\0")
        h.update(path.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


@functools.lru_cache(maxsize=1)
def git_commit() -> str | None:
    """The checkout's commit (``+dirty`` when the package has uncommitted changes), None outside git."""
    root = PACKAGE_DIR.parent
    if not (root / ".git").exists():
        return None
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True,
                              timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "rftstatic"], cwd=root, capture_output=True,
                               text=True, timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return head + ("+dirty" if dirty else "")


def peak_memory_mb() -> float:
    """Peak resident memory of this process so far [MB]."""
    r = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return r / 1024**2 if sys.platform == "darwin" else r / 1024  # bytes on macOS, KiB on Linux


def software() -> dict:
    """What ran: package version, git commit, code fingerprint (12 hex digits) and the Python version."""
    return {"rftstatic": __version__, "git_commit": git_commit(), "code": code_fingerprint()[:12],
            "python": platform.python_version()}
