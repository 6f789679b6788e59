"""Output writers: VTU/PVD/JSON round trips, atomicity, and that every figure is written."""

import json
import math
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from rftstatic.io import animation, charts, outlines, views
from rftstatic.io import files as output


def rectangle(nx=5, ny=5, lx=4.0, ly=2.0):
    """(N, 3) grid nodes on z = 0 and (E, 3) CCW triangles, two per cell."""
    xs, ys = np.meshgrid(np.linspace(0, lx, nx), np.linspace(0, ly, ny), indexing="xy")
    X3 = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(nx * ny)])
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), indexing="xy")
    a = (j * nx + i).ravel()
    b, c, d = a + 1, a + nx + 1, a + nx
    tri = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return X3, tri


def draped(X3):
    """A smooth bent surface (a cloth hanging over a ridge along y)."""
    x = X3.copy()
    x[:, 2] = -0.5 * (x[:, 0] - 2.0) ** 2 + 0.2 * np.sin(3 * x[:, 1])
    return x


def png_ok(path):
    data = path.read_bytes()
    return len(data) > 1000 and data[:8] == b"\x89PNG\r\n\x1a\n"


def no_temp_files(directory):
    return [p.name for p in directory.iterdir() if ".tmp" in p.name] == []


def test_import_is_light():
    code = ("import sys, rftstatic.io.files, rftstatic.io.figure, rftstatic.io.surface, rftstatic.io.views, "
            "rftstatic.io.charts, rftstatic.io.animation, rftstatic.io.outlines, rftstatic.io.drape_figures; "
            "print('matplotlib' in sys.modules, 'meshio' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]


def test_vtu_round_trip_in_scene_units(tmp_path):
    import meshio

    X3, tri = rectangle()
    rng = np.random.default_rng(0)
    U = 0.01 * rng.standard_normal(X3.shape)
    E = len(tri)
    fields = {"curvature": rng.standard_normal((E, 3)), "relative_curvature": rng.random(E),
              "membrane_strain": rng.standard_normal((E, 3))}
    path = output.write_vtu(tmp_path / "drape.vtu", X3, U, tri, length_unit_scale=0.01,
                            point_data={"speed": np.arange(len(X3), dtype=float)}, cell_data=fields)
    mesh = meshio.read(path)
    np.testing.assert_allclose(mesh.points, (X3 + U) / 0.01, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(mesh.point_data["displacement"], U / 0.01, rtol=1e-12)
    np.testing.assert_array_equal(mesh.point_data["speed"], np.arange(len(X3)))
    np.testing.assert_array_equal(mesh.cells_dict["triangle"], tri)
    for name, value in fields.items():
        got = mesh.cell_data[name][0]
        assert got.shape == value.shape
        np.testing.assert_allclose(got, value)
    assert no_temp_files(tmp_path)


def test_vtu_rejects_wrong_field_length(tmp_path):
    X3, tri = rectangle()
    with pytest.raises(ValueError, match="relative_curvature"):
        output.write_vtu(tmp_path / "bad.vtu", X3, 0 * X3, tri, cell_data={"relative_curvature": np.ones(3)})
    assert list(tmp_path.iterdir()) == []


def test_pvd_is_wellformed_collection(tmp_path):
    entries = [(0.0, "frame_0000.vtu"), (0.16, tmp_path / "frame_0001.vtu"), (2.0, "sub/frame_0002.vtu")]
    path = output.write_pvd(tmp_path / "series.pvd", entries)
    root = ET.parse(path).getroot()
    assert root.tag == "VTKFile" and root.get("type") == "Collection"
    sets = root.find("Collection").findall("DataSet")
    assert [float(d.get("timestep")) for d in sets] == [0.0, 0.16, 2.0]
    assert [d.get("file") for d in sets] == ["frame_0000.vtu", "frame_0001.vtu", "sub/frame_0002.vtu"]


def test_json_numpy_types_and_nonfinite(tmp_path):
    from dataclasses import dataclass

    @dataclass
    class Result:
        iterations: int
        residual: np.ndarray

    data = {"n": np.int64(3), "x": np.float32(0.5), "ok": np.bool_(True), "a": np.arange(3),
            "m": np.array([[1.0, np.nan], [np.inf, -2.0]]), "bad": float("nan"), 7: (1, 2),
            "res": Result(2, np.array([1e-3, 1e-9]))}
    path = output.write_json(tmp_path / "summary.json", data)
    text = path.read_text()
    assert "NaN" not in text and "Infinity" not in text
    back = json.loads(text)
    assert back == {"n": 3, "x": 0.5, "ok": True, "a": [0, 1, 2], "m": [[1.0, None], [None, -2.0]],
                    "bad": None, "7": [1, 2], "res": {"iterations": 2, "residual": [1e-3, 1e-9]}}
    assert text.startswith("{\n  ")


def test_atomic_write_keeps_old_file_when_writer_raises(tmp_path):
    target = tmp_path / "summary.json"
    output.write_json(target, {"version": 1})
    with pytest.raises(RuntimeError), output.atomic_write(target) as tmp:
        tmp.write_text('{"version": 2, "trunc')
        raise RuntimeError("interrupted")
    assert json.loads(target.read_text()) == {"version": 1}
    assert no_temp_files(tmp_path)
    with pytest.raises(TypeError):
        output.write_json(tmp_path / "new.json", {"x": object()})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.json"]


def test_plot_views_writes_three_pngs(tmp_path):
    X3, tri = rectangle()
    x = draped(X3)
    kappa = np.linspace(0, 1, len(tri))
    obstacle = outlines.outline_drawer(outlines.outline_square(2.0, 1.0, 0.5, corner_radius=0.1), z=0.0)
    out = views.plot_views(tmp_path / "drape", x, tri, title="test", color_by=kappa, frame_x0=X3,
                           obstacles_draw=[obstacle], length_unit="cm", color_label="relative curvature")
    assert set(out) == {"side", "top", "iso"}
    for view, path in out.items():
        assert path.name == f"drape_{view}.png" and png_ok(path)
    assert png_ok(views.plot_views(tmp_path / "plain", x, tri, views=("top",))["top"])
    assert no_temp_files(tmp_path)


def test_boundary_profiles_history_load_deflection(tmp_path):
    s = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    curves = {"reference": np.column_stack([10 * np.cos(s), 10 * np.sin(s)]),
              "RFT6": np.column_stack([9 * np.cos(s), 9.5 * np.sin(s)])}
    assert png_ok(charts.plot_boundary_overlay(tmp_path / "b.png", curves, title="Fig. 6a",
                                               reference_label="reference",
                                               obstacle_outline=outlines.outline_square(0, 0, 5)))
    xs = np.linspace(0, 5, 20)
    prof = {"RFT3": np.column_stack([xs, -0.05 * xs**2]), "RFT6": np.column_stack([xs, -0.04 * xs**2])}
    assert png_ok(charts.plot_side_profiles(tmp_path / "p.png", prof, title="Fig. 5b",
                                            reference=prof["RFT6"][::4] + 0.01))
    t = np.linspace(0, 1, 50)
    assert png_ok(charts.plot_history(tmp_path / "h.png", t, {"kinetic": t**2, "potential": 1 - t},
                                      xlabel="t [s]", ylabel="energy", title="energies", logy=True))
    load = np.linspace(0, 1, 11)
    assert png_ok(charts.plot_load_deflection(tmp_path / "ld.png", {"RFT6": (load, 3 * load)},
                                              {"S4R": (load[::2], 3 * load[::2] + 0.05)},
                                              xlabel="tip deflection", ylabel="load fraction",
                                              title="end shear"))


def test_plot_convergence_fits_rate(tmp_path):
    n = np.array([100.0, 400.0, 1600.0, 6400.0])
    series = {"RFT6": (n, 3.0 * n**-2.0), "RFT3": (n, 0.5 * n**-1.0),
              "broken": (n, [1e-2, 0.0, np.nan, 1e-3])}
    path, slopes = charts.plot_convergence(tmp_path / "c.png", series, xlabel="nodes", title="convergence")
    assert png_ok(path)
    assert slopes["RFT6"] == pytest.approx(-2.0, abs=1e-12)
    assert slopes["RFT3"] == pytest.approx(-1.0, abs=1e-12)
    assert slopes["broken"] == pytest.approx(math.log(0.1) / math.log(64.0))


def test_animate_writes_gif(tmp_path):
    from PIL import Image

    X3, tri = rectangle()
    frames = [X3 + s * (draped(X3) - X3) for s in (0.0, 0.5, 1.0)]
    path = animation.animate(tmp_path / "drop.gif", frames, tri, times=[0.0, 0.16, 0.32], fps=5)
    with Image.open(path) as im:
        assert im.format == "GIF" and im.n_frames == 3
    assert png_ok(views.plot_views(tmp_path / "a", frames[-1], tri, views=("side",))["side"])
    assert no_temp_files(tmp_path)


def test_outlines_closed_ccw():
    for pts in (outlines.outline_square(1, 2, 3), outlines.outline_square(1, 2, 3, corner_radius=0.5),
                outlines.outline_circle(1, 2, 3, n=64)):
        np.testing.assert_allclose(pts[0], pts[-1])
        x, y = pts[:, 0], pts[:, 1]
        assert 0.5 * np.sum(x[:-1] * y[1:] - x[1:] * y[:-1]) > 0
    sq = outlines.outline_square(1, 2, 3)
    assert sq[:, 0].min() == -2 and sq[:, 1].max() == 5
