"""Result files: deformed meshes (VTU), time-series indices (PVD) and summaries (JSON).

Every writer goes through :func:`atomic_write`: the data are written to a temporary file in the
destination directory and moved over the destination with :func:`os.replace`, which is atomic on POSIX
and Windows. An interrupted or failing run therefore leaves either the previous file or the complete new
one, never a truncated file that ParaView or a later ``json.load`` would choke on.

Units. The package works in SI; the files are in the scene's units (DEVELOPERS.md). :func:`write_vtu`
takes ``length_unit_scale``, the SI value of one scene length unit (0.01 for a ``cm-gf-s`` scene), and
divides positions and the "displacement" field by it. Any other field is written as given: convert it
before the call (a curvature in 1/m becomes 1/cm by multiplying by ``length_unit_scale``).

meshio is imported inside :func:`write_vtu` so that importing this module is free.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import os
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, Iterable, Iterator, Mapping

import numpy as np

__all__ = ["atomic_write", "write_vtu", "write_pvd", "write_json", "to_jsonable"]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; move it onto ``path`` when the block succeeds.

    The temporary name keeps the extension of ``path`` (``.out.vtu`` -> ``..out.vtu.<random>.tmp.vtu``)
    because meshio, matplotlib and Pillow pick the format from it. If the block raises, the temporary file
    is removed and ``path`` is left untouched. The final file gets the usual permissions
    (``0o666 & ~umask``), not the private ones of :func:`tempfile.mkstemp`.

    Parameters
    ----------
    path : destination file; its directory must exist.

    Yields
    ------
    tmp : Path of the temporary file (already created, empty) to write to.
    """
    dest = Path(path)
    directory = dest.parent if str(dest.parent) else Path(".")
    if not directory.is_dir():
        raise FileNotFoundError(f"cannot write {str(dest)!r}: directory {str(directory)!r} does not exist")
    fd, tmp_name = tempfile.mkstemp(dir=directory, prefix=f".{dest.name}.", suffix=f".tmp{dest.suffix}")
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        with open(tmp, "rb+") as fh:  # flush the data to disk before the rename makes it visible
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, dest)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise


def _check_field(kind: str, name: str, value: Any, n: int) -> np.ndarray:
    arr = np.asarray(value)
    if arr.ndim == 0 or arr.shape[0] != n:
        count = "len(points)" if kind == "point" else "len(cells)"
        raise ValueError(f"{count} = {n}, but {kind}_data[{name!r}] has shape {arr.shape}; "
                         f"give one row per {'node' if kind == 'point' else 'triangle'}")
    return arr


def write_vtu(path: str | os.PathLike, X3: np.ndarray, U: np.ndarray, tri: np.ndarray, *,
              length_unit_scale: float = 1.0, point_data: Mapping[str, Any] | None = None,
              cell_data: Mapping[str, Any] | None = None) -> Path:
    """Write the deformed triangle mesh to a VTK XML unstructured grid (``.vtu``).

    Parameters
    ----------
    path : destination file (``.vtu``).
    X3 : (N, 3) reference positions [m].
    U : (N, 3) displacements [m].
    tri : (E, 3) node indices of the triangles (counter-clockwise).
    length_unit_scale : SI value of one scene length unit [m] (0.01 for cm); points and the
        "displacement" field are divided by it.
    point_data : extra nodal fields, each (N,) or (N, k), written as given (scene units).
    cell_data : extra triangle fields, each (E,) or (E, k), e.g. "curvature" (E, 3),
        "relative_curvature" (E,), "membrane_strain" (E, 3), written as given.

    Returns
    -------
    The destination path. Points in the file are ``(X3 + U) / length_unit_scale``.
    """
    import meshio

    X3 = np.asarray(X3, dtype=float)
    U = np.asarray(U, dtype=float)
    tri = np.asarray(tri)
    if X3.ndim != 2 or X3.shape[1] != 3:
        raise ValueError(f"X3 must have shape (N, 3), got {X3.shape}")
    if U.shape != X3.shape:
        raise ValueError(f"U must have the shape of X3 {X3.shape}, got {U.shape}")
    if tri.ndim != 2 or tri.shape[1] != 3 or not np.issubdtype(tri.dtype, np.integer):
        raise ValueError(f"tri must be an integer (E, 3) array, got {tri.dtype} {tri.shape}")
    n, e = len(X3), len(tri)
    if e and (tri.min() < 0 or tri.max() >= n):
        raise ValueError(f"tri refers to node {int(tri.max()) if tri.max() >= n else int(tri.min())}, "
                         f"but there are {n} nodes")
    scale = float(length_unit_scale)
    if not (math.isfinite(scale) and scale > 0):
        raise ValueError(f"length_unit_scale must be a positive number [m], got {length_unit_scale!r}")

    pdata = {"displacement": U / scale}
    for name, value in (point_data or {}).items():
        pdata[name] = _check_field("point", name, value, n)
    cdata = {name: [_check_field("cell", name, value, e)] for name, value in (cell_data or {}).items()}
    mesh = meshio.Mesh((X3 + U) / scale, [("triangle", tri.astype(np.int64))],
                       point_data=pdata, cell_data=cdata)
    with atomic_write(path) as tmp:
        meshio.write(tmp, mesh, file_format="vtu")
    return Path(path)


def write_pvd(path: str | os.PathLike, entries: Iterable[tuple[float, str | os.PathLike]]) -> Path:
    """Write a ParaView collection (``.pvd``) that indexes a time series of ``.vtu`` files.

    Parameters
    ----------
    path : destination file (``.pvd``).
    entries : (time, vtu_filename) pairs, time in scene units. A filename is stored relative to the
        directory of ``path`` when it lies below it (ParaView resolves it from there), else as given.

    Returns
    -------
    The destination path.
    """
    base = Path(path).resolve().parent
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    collection = ET.SubElement(root, "Collection")
    for k, (time, name) in enumerate(entries):
        t = float(time)
        if not math.isfinite(t):
            raise ValueError(f"entry {k} of the PVD {str(path)!r} has time {time!r}; times must be finite")
        fname = Path(name)
        if fname.is_absolute():
            with contextlib.suppress(ValueError):
                fname = fname.relative_to(base)
        ET.SubElement(collection, "DataSet", timestep=repr(t), group="", part="0", file=fname.as_posix())
    ET.indent(root)
    with atomic_write(path) as tmp:
        ET.ElementTree(root).write(tmp, encoding="utf-8", xml_declaration=True)
    return Path(path)


def to_jsonable(obj: Any) -> Any:
    """Return ``obj`` made of plain Python types that :func:`json.dump` accepts.

    numpy scalars and arrays become numbers and (nested) lists; NaN and infinities become ``None``
    (JSON has no such numbers); tuples and sets become lists; dict keys become strings; paths become
    strings; dataclass instances become dicts of their fields.
    """
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, (int, np.integer)) and not isinstance(obj, np.bool_):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, (float, np.floating)):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, (complex, np.complexfloating)):
        raise TypeError(f"cannot write the complex number {obj!r} to JSON; "
                        "store its real and imaginary parts")
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "fc" or obj.dtype == object:
            return [to_jsonable(v) for v in obj.tolist()] if obj.ndim else to_jsonable(obj.item())
        return obj.tolist()
    if isinstance(obj, Mapping):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, set, frozenset)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: to_jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    raise TypeError(f"cannot write an object of type {type(obj).__name__} to JSON: {obj!r:.80}")


def write_json(path: str | os.PathLike, data: Any) -> Path:
    """Write ``data`` to ``path`` as indented JSON (``indent=2``), atomically.

    ``data`` goes through :func:`to_jsonable` first, so numpy types are accepted and NaN/inf are
    written as ``null``. Returns the destination path.
    """
    text = json.dumps(to_jsonable(data), indent=2, allow_nan=False)
    with atomic_write(path) as tmp:
        tmp.write_text(text + "\n", encoding="utf-8")
    return Path(path)
