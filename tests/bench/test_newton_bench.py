"""bench newton: its child functions return what the table prints, and its report is written."""

from types import SimpleNamespace

from rftstatic.bench import newton


def test_strip_solve_reports_iterations_factorisations_and_error():
    r = newton.strip_solve(11, 3, warm=True)
    assert r["converged"] and r["iterations"] > 0
    assert r["factorisations"] >= r["iterations"]  # one per iteration, plus the first increment's rate
    assert abs(r["error"]) < 0.05 and r["warm_solve_s"] > 0


def test_stiff_cell_converges_and_report_is_written(tmp_path):
    r = newton.strip_solve(11, 3, element="RFT3", ratio=1e9)
    assert r["converged"]
    rows = []
    newton._row(rows, "strip 11x3 RFT3 C/B 1e+09", r, SimpleNamespace(wall_s=1.5), "converged True")
    path = newton.write_report(tmp_path, rows, "", ("0.10", "0.20"))
    text = path.read_text()
    assert "strip 11x3 RFT3 C/B 1e+09" in text and "| 1.500 |" in text and "Targets" in text
    assert (tmp_path / "newton.json").exists()
