"""numpy's BLAS runs on one thread once rftstatic is imported, whether numpy was imported before or after it
(``rftstatic/__init__.py``): a threaded dot product of a drape's free dofs waits for a time slice on a busy machine."""

import json
import os
import subprocess
import sys

import pytest

PROBE = """
import json, sys
{first}
from threadpoolctl import threadpool_info
print(json.dumps([[i["internal_api"], i["num_threads"]] for i in threadpool_info() if i["user_api"] == "blas"]))
"""


def blas_threads(first: str, env_threads: str | None = None) -> list:
    # OpenBLAS also reads GOTO_NUM_THREADS and OMP_NUM_THREADS (other tests or the machine may set them)
    names = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")
    env = {k: v for k, v in os.environ.items() if k not in names}
    if env_threads is not None:
        env["OPENBLAS_NUM_THREADS"] = env_threads
    out = subprocess.run([sys.executable, "-c", PROBE.format(first=first)], env=env, capture_output=True, text=True,
                         check=True, timeout=120)
    return json.loads(out.stdout.strip().splitlines()[-1])


needs_cores = pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="one core: OpenBLAS starts one thread anyway")


@needs_cores
@pytest.mark.parametrize("first", ["import numpy\nimport rftstatic", "import rftstatic\nimport numpy"])
def test_numpy_blas_on_one_thread(first):
    pools = blas_threads(first)
    assert pools, "numpy's BLAS not found by threadpoolctl"
    assert all(threads == 1 for _, threads in pools), pools


@needs_cores
def test_numpy_first_without_rftstatic_keeps_its_threads():
    """The probe can tell: numpy alone starts more than one BLAS thread on this machine."""
    assert max(threads for _, threads in blas_threads("import numpy")) > 1


@needs_cores
def test_user_setting_wins():
    assert all(threads == 2 for _, threads in blas_threads("import numpy\nimport rftstatic", env_threads="2"))
