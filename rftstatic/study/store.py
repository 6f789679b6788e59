"""What a study keeps: point keys, ``results.csv`` (one row per finished point) and ``study.json``.

A point's key is a hash of its resolved scene (after the study's and the point's ``--set`` overrides),
the contents of a mesh file it reads, and :func:`rftstatic.provenance.code_fingerprint`: the same
scene with the same code is the same result, and a result of other code is never reused. The point
runs in ``DIR/points/KEY/`` (``summary.json``, ``deformed.vtu``, ``point.json``: its row).

``results.csv`` is rewritten as a whole, atomically (:func:`rftstatic.io.files.atomic_write`: a
temporary file, fsync, rename), after each finished point, so that a killed driver leaves the previous
table or the new one, never half a row. A worker writes its row into ``point.json`` as well, so a
point that finished while the driver was down is recovered from its folder at the next start.
"""

from __future__ import annotations

import csv
import hashlib
import json
import time
from pathlib import Path

from rftstatic.io.files import atomic_write, write_json
from rftstatic.provenance import code_fingerprint

FIXED_FIRST = ["key", "status"]
FIXED_LAST = ["converged", "route", "wall_time_s", "worker", "folder", "error"]
STATUSES = ("ok", "not converged", "failed")
"""A row's status: converged; ran but ``converged = false`` (a result all the same); raised an error."""


def point_key(scene) -> str:
    """16 hex digits of the SHA-1 of the resolved scene, its mesh file and the code fingerprint."""
    payload = {"scene": scene.name, "data": scene.data, "code": code_fingerprint()}
    mesh = scene.data.get("mesh", {})
    if mesh.get("kind") == "file" and scene.path is not None:
        path = (Path(scene.path).parent / mesh.get("path", "")).resolve()
        payload["mesh_file"] = hashlib.sha1(path.read_bytes()).hexdigest() if path.is_file() else str(path)
    text = json.dumps(payload, sort_keys=True, default=str)
    return hashlib.sha1(text.encode()).hexdigest()[:16]


TEXT_COLUMNS = ("key", "worker", "folder")
"""Columns of ``results.csv`` read back as text, never decoded (a hex key can read as a number)."""


def encode(value) -> str:
    """A cell of ``results.csv``: empty for None, JSON for lists, ``repr`` precision for floats."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (list, dict)):
        return json.dumps(value)
    return str(value)


def decode(text: str):
    """Inverse of :func:`encode` for numbers, booleans and JSON lists; other text stays text."""
    if text == "":
        return None
    if text in ("true", "false"):
        return text == "true"
    try:
        return json.loads(text)
    except ValueError:
        return text


class Store:
    """The rows of a study in ``out/results.csv``, keyed by point key.

    Parameters
    ----------
    out : the study folder (created)
    columns : the varied keys and the measures, in order (``key`` and ``status`` come first; converged,
        route, wall time, worker, folder and error last)
    """

    def __init__(self, out: Path, columns: list[str]):
        self.out = Path(out)
        self.out.mkdir(parents=True, exist_ok=True)
        (self.out / "points").mkdir(exist_ok=True)
        self.path = self.out / "results.csv"
        self.columns = FIXED_FIRST + [c for c in columns if c not in FIXED_FIRST + FIXED_LAST] + FIXED_LAST
        self.rows: dict[str, dict] = {}
        self.recovered = 0
        self._read()

    def folder(self, key: str) -> Path:
        return self.out / "points" / key

    def _read(self) -> None:
        if self.path.exists():
            with open(self.path, newline="", encoding="utf-8") as fh:
                reader = csv.DictReader(fh)
                for name in reader.fieldnames or []:
                    if name not in self.columns:  # a column of an earlier run (another measure): kept
                        self.columns.insert(len(self.columns) - len(FIXED_LAST), name)
                for row in reader:  # the key is hex text: "55159628e9139277" must not decode to a float (inf)
                    self.rows[row["key"]] = {k: v if k in TEXT_COLUMNS else decode(v) for k, v in row.items()}

    def recover(self, keys) -> int:
        """Rows of points among ``keys`` that finished (``point.json`` in their folder) but are not in
        ``results.csv`` (the driver was killed before it wrote them); written; returns how many."""
        found = 0
        for key in keys:
            f = self.folder(key) / "point.json"
            if key not in self.rows and f.exists():
                try:
                    row = json.loads(f.read_text(encoding="utf-8"))
                except ValueError:
                    continue
                self.rows[key] = row
                found += 1
        if found:
            self.write()
        self.recovered += found
        return found

    def done(self, key: str, *, retry_failed: bool = False, needs=()) -> bool:
        """Whether ``key`` has a row (a failed one counts unless ``retry_failed``) with the ``needs`` columns."""
        row = self.rows.get(key)
        if row is None or (retry_failed and row.get("status") == "failed"):
            return False
        return row.get("status") == "failed" or all(n in row for n in needs)

    def add(self, row: dict) -> None:
        """Keep ``row`` and rewrite ``results.csv`` atomically."""
        for name in row:
            if name not in self.columns:
                self.columns.insert(len(self.columns) - len(FIXED_LAST), name)
        self.rows[row["key"]] = row
        self.write()

    def write(self) -> None:
        with atomic_write(self.path) as tmp:
            with open(tmp, "w", newline="", encoding="utf-8") as fh:
                writer = csv.DictWriter(fh, fieldnames=self.columns, extrasaction="ignore")
                writer.writeheader()
                for row in self.rows.values():
                    writer.writerow({c: encode(row.get(c)) for c in self.columns})


def record_run(out: Path, info: dict, run: dict) -> Path:
    """Write ``out/study.json``: ``info`` (command, scene, keys, points) and the list of ``runs`` (engine,
    scheduler address, workers, points run), this ``run`` appended to the earlier ones."""
    path = Path(out) / "study.json"
    runs = []
    if path.exists():
        try:
            runs = json.loads(path.read_text(encoding="utf-8")).get("runs", [])
        except ValueError:
            runs = []
    run = {"finished": time.strftime("%Y-%m-%dT%H:%M:%S%z"), **run}
    return write_json(path, {**info, "code": code_fingerprint()[:12], "runs": [*runs, run]})
