"""The drape run cache (rftstatic.bench.drape.run_cached, validate's out/validate-drape) keys on the code."""

import json
import shutil
from pathlib import Path

from rftstatic import provenance
from rftstatic.bench import drape
from rftstatic.validate import drape_common

SCENE, NODES = "pedestal-square-20", (9, 9)


def test_a_changed_code_fingerprint_misses_the_drape_cache(tmp_path, monkeypatch):
    monkeypatch.setattr(drape_common, "cache_root", lambda: tmp_path)
    monkeypatch.delenv("RFTSTATIC_DRAPE_REFRESH", raising=False)
    monkeypatch.delenv("RFTSTATIC_DRAPE_CACHED_ONLY", raising=False)
    first = drape_common.drape_run(SCENE, NODES, "RFT6", figures=False)  # solved in a child interpreter
    version = provenance.code_fingerprint()[:12]
    assert first["converged"] and first["software"]["code"] == version  # the child ran this code
    assert Path(first["dir"]).name == f"{SCENE}_n9x9_RFT6_code-{version}"
    assert first["process_s"] >= first["wall_s"] > 0 and first["cpu_s"] > 0 and first["peak_rss_mb"] > 50

    calls = []

    def fake_run_one(name, overrides, out, *, figures=True, timeout=None):
        """Stands in for a solve: the first run's files, stamped with the code version of now."""
        calls.append(Path(out))
        shutil.copytree(first["dir"], out)
        rec = json.loads((Path(out) / "record.json").read_text())
        rec["software"]["code"] = drape.code_version()
        (Path(out) / "record.json").write_text(json.dumps(rec))

    monkeypatch.setattr(drape, "run_one", fake_run_one)
    again = drape_common.drape_run(SCENE, NODES, "RFT6")
    assert not calls and again["dir"] == first["dir"]  # same code: reused

    monkeypatch.setattr(provenance, "code_fingerprint", lambda: "f" * 40)  # "the package was edited"
    monkeypatch.setenv("RFTSTATIC_DRAPE_CACHED_ONLY", "1")
    assert drape_common.drape_run(SCENE, NODES, "RFT6") is None  # the old run is not offered
    assert drape_common.run_cached_only(SCENE, NODES, "RFT6") is None
    monkeypatch.delenv("RFTSTATIC_DRAPE_CACHED_ONLY")
    other = drape_common.drape_run(SCENE, NODES, "RFT6")
    assert len(calls) == 1 and other["dir"] == str(tmp_path / f"{SCENE}_n9x9_RFT6_code-ffffffffffff")
    assert drape_common.run_cached_only(SCENE, NODES, "RFT6")["dir"] == other["dir"]


def test_a_record_of_other_code_under_this_key_is_not_reused(tmp_path):
    """The key is the parent's fingerprint; the record says what the child ran: both must agree."""
    overrides = [f"mesh.nodes=[{NODES[0]},{NODES[1]}]", "element=RFT6"]
    d = tmp_path / drape.run_key(SCENE, overrides)
    d.mkdir()
    (d / "state.npz").write_bytes(b"")
    (d / "record.json").write_text(json.dumps({"software": {"code": "0123456789ab"}}))
    assert drape.cached_dir(SCENE, overrides, root=tmp_path) is None
    (d / "record.json").write_text(json.dumps({"software": {"code": drape.code_version()}}))
    assert drape.cached_dir(SCENE, overrides, root=tmp_path) == d
