"""``python -m rftstatic pattern FILE``: a pattern read, meshed, checked, described and written; bad input exit 2."""

from pathlib import Path

import meshio
import numpy as np

from rftstatic.cli import main

ROOT = Path(__file__).resolve().parents[2]


def test_the_a_line_skirt_is_described_and_written(tmp_path, capsys):
    code = main(["pattern", str(ROOT / "cases" / "patterns" / "skirt-a-line.toml"), "--h", "4", "--out",
                 str(tmp_path)])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "2 panels, 2 seams" in out and "front:1 - back:3" in out and "60.00 / 60.00" in out
    mesh = meshio.read(tmp_path / "pattern.vtu")
    panel = mesh.point_data["panel"]
    assert set(np.unique(panel)) == {0.0, 1.0}
    # as placed: the back panel is turned about the vertical, 36 cm behind the front (z from -18 to +18 cm)
    z = mesh.points[:, 2]
    assert np.allclose(sorted({round(v, 6) for v in z}), [-18.0, 18.0])


def test_a_seam_to_a_missing_edge_exits_2_naming_panel_and_edge(tmp_path, capsys):
    text = (ROOT / "cases" / "patterns" / "skirt-a-line.toml").read_text().replace('b = "back:3"', 'b = "back:7"')
    assert 'b = "back:7"' in text
    path = tmp_path / "bad.toml"
    path.write_text(text)
    code = main(["pattern", str(path), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "back" in err and "7" in err and str(path) in err and "Traceback" not in err
