"""Bad fabric input and the seeds cap on the command line (issue 35 item 6): each an input error (exit 2) of
one line naming the scene file and the key; ``--set solver.seeds=5`` runs on the Cusick scene's own route and
its summary keeps the seeds' means."""

import json

import pytest

from rftstatic.cli import main
from rftstatic.scenes.run_options import MAX_SEEDS

KES = "material={kes_B_warp=0.083, kes_B_weft=0.063, kes_W=19.0, kes_T=0.5}"


def _run(capsys, tmp_path, sets, scene="cusick-30"):
    argv = ["case", scene, *(a for kv in sets for a in ("--set", kv)), "--out", str(tmp_path / "o"), "--no-figures"]
    code = main(argv)
    return code, capsys.readouterr().err.strip()


@pytest.mark.parametrize("sets, key, fragment", [
    (["material={kes_B_warp=25.0, kes_B_weft=0.063, kes_W=19.0, kes_T=0.5}"], "material.kes_B_warp",
     "outside the plausible range [0.0005, 20] gf cm^2/cm"),
    (["material={kes_B_warp=0.083, kes_B_weft=0.063, kes_W=1e4, kes_T=0.5}"], "material.kes_W",
     "618 fabrics of Feng et al. (2022)"),
    (["material={kes_B_warp=0.083, kes_B_weft=0.063, kes_T=0.5}"], "material.kes_W", "is given without kes_W"),
    (["material={kes_B_warp=0.0, kes_B_weft=0.063, kes_W=19.0, kes_T=0.5}"], "material.kes_B_warp", "must be > 0"),
    (["material={kes_B_warp=0.083, kes_B_weft=0.063, kes_W=19.0, kes_T=-0.5}"], "material.kes_T", "must be > 0"),
    (["material.kes_B_warp=0.1"], "material.kes_B_warp", 'next to preset = "wool-kang-yu"'),
    ([f"solver.seeds={MAX_SEEDS + 1}"], "solver.seeds", f"must be in [1, {MAX_SEEDS}]"),
])
def test_bad_fabric_input_is_an_input_error(capsys, tmp_path, sets, key, fragment):
    code, err = _run(capsys, tmp_path, sets)
    assert code == 2, err
    assert "\n" not in err and "Traceback" not in err, err
    assert f"cusick-30.toml: {key}: " in err and fragment in err, err


def test_five_seeds_of_a_kes_fabric_run_on_the_cusick_route(capsys, tmp_path):
    """A coarse Cusick specimen (4 rings x 80) of a KES-only fabric with five seeded starts: the summary keeps
    the seeds' mean drape coefficient and fold count, and lists the filled values."""
    code, err = _run(capsys, tmp_path, [KES, "mesh.nodes=[4,80]", "solver.seeds=5"])
    assert code == 0, err
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    seeds = s["seeds"]
    assert seeds["count"] == 5 and seeds["solved"] == 5
    assert min(seeds["fold_counts"]) <= seeds["fold_count_mean"] <= max(seeds["fold_counts"])
    assert 0 < seeds["drape_coefficient_percent_mean"] < 100
    assert s["material"]["filled"]["C_warp"]["value"] == pytest.approx(398.4)
