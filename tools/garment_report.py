"""Write validation/garments.md: garments sewn from panels on the dress form, measured by independent checks.

    python tools/garment_report.py [--out validation] [--a-line-h 1.45 1.1] [--circle-h 1.48 1.1] [--dress-h 1.1 0.9]
                                   [--carry-h 0.8] [--no-fabrics] [--work DIR] [--reuse] [--timeout S]

Every number comes from a whole-process run made here (``python -m rftstatic case SCENE --set garment.h=H``), one
after the other: each scene on its own mesh (the whole ``case`` command, figures and all, timed: the issue's time
limits) and on a finer one (``--no-figures``): convergence and stability, the seams (largest gap at the start and at
the merge), the independent crossing check of the garment against the form itself (``body.obj``, not the contact
surface) and against itself, the hem's drape coefficient and fold count on each mesh (the fold count against the
finer mesh), and the cost of each stage (closing levels, static solve). The circle skirt's drapes are also carried
between its meshes (and to ``--carry-h``) and solved there (:func:`_carried`): which drapes each mesh holds. The four
fabrics transcribed from Matsudaira et al. (2015) run ``cusick-30`` and ``skirt-circle`` each (:func:`_fabric_section`).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


REUSE = False
"""``--reuse``: take a run folder that already holds a finished run's summary.json instead of running it again
(its whole-process wall time as this tool measured it, from :data:`WALL_FILE`; not shown for a run made by hand),
waiting up to ``--timeout`` for one under way in another process (its ``.partial`` folder)."""
WALL_FILE = "report-wall.json"
"""The whole-process wall time [s] of a run this tool made, kept in its folder so that ``--reuse`` can show it."""
TIMEOUT = 900.0
"""Longest whole-process run [s] (``--timeout``); a run stopped there is a row with exit ``timeout``."""


def _run(scene, h, out, figures, sets=()):
    partial = out.with_name(out.name + ".partial")
    t = time.perf_counter()
    while REUSE and partial.is_dir() and not (out / "summary.json").is_file() and time.perf_counter() - t < TIMEOUT:
        time.sleep(10.0)  # the same run under way in another process (--reuse): wait for it
    if REUSE and partial.is_dir() and not (out / "summary.json").is_file():
        return "timeout", time.perf_counter() - t, None, [f"still running in another process after {TIMEOUT:.0f} s"]
    if REUSE and (out / "summary.json").is_file():
        timed = out / WALL_FILE  # the whole-process time this tool measured for that run, if it did
        wall = json.loads(timed.read_text())["wall_s"] if timed.is_file() else float("nan")
        return 0, wall, json.loads((out / "summary.json").read_text()), []
    t = time.perf_counter()
    try:
        p = subprocess.run([sys.executable, "-m", "rftstatic", "case", scene, "--set", f"garment.h={h}", "--out",
                            str(out)] + [a for k in sets for a in ("--set", k)] + ([] if figures else ["--no-figures"]),
                           capture_output=True, text=True, cwd=ROOT, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return "timeout", time.perf_counter() - t, None, [f"stopped after {TIMEOUT:.0f} s (--timeout)"]
    wall = time.perf_counter() - t
    summary = json.loads((out / "summary.json").read_text()) if p.returncode == 0 else None
    if summary is not None:
        (out / WALL_FILE).write_text(json.dumps({"wall_s": wall, "figures": figures}))
    return p.returncode, wall, summary, (p.stdout + p.stderr).strip().splitlines()[-1:] if p.returncode else []


def _wall(wall, figures) -> str:
    if wall != wall:  # NaN: a reused run
        return "(reused run)"
    return f"{wall:.0f}{' (with figures)' if figures else ''}"


def _table(rows) -> list:
    """The measures of each run of one scene, a markdown table."""
    out = ["| h [cm] | exit | mean element [cm] | converged | stable | Newton its (last try) | "
           "largest gap start / merged [cm] | closing [s sim, steps, s wall] | body crossings | smallest distance to form [cm] | clearance [cm] | "
           "self crossings | hem DC | hem folds | nodes | static solve [s] | wall [s] |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for h, code, wall, s, err, figures in rows:
        if s is None:
            out.append(f"| {h:g} | {code} | | | | | | | | | | | | | | | {wall:.0f} |")
            continue
        g = s["garment"]
        out.append(
            f"| {h:g} | {code} | {g['mean_element_size']:.2f} | {s['converged']} | {s['stable_minimum']} | "
            f"{s['newton_iterations']} | {g['largest_seam_gap_start']:.1f} / {g['largest_seam_gap']:.3f} | "
            f"{g['closing_time']:.2f}, {g['closing_steps']}, {g['closing_wall_time']:.0f} | "
            f"{g['body_crossing_pairs']} | "
            f"{g['body_smallest_distance']:.3f} | {g['contact_clearance']:.3f} | {s['self_intersections']['pairs']} | "
            f"{g['hem_drape_coefficient']:.4f} | {g['hem_folds']} | {s['nodes']} | {s['wall_time_s']:.0f} | "
            f"{_wall(wall, figures)} |")
    out += [f"\nh = {h:g}: exit {code}: {' '.join(err)}" for h, code, wall, s, err, _ in rows if s is None]
    out += [f"\nh = {h:g}: {s['garment']['crease_edges']} crease edges, off their rest angle by "
            f"{s['garment']['crease_off_rest_mean_deg']:.1f} deg on average, {s['garment']['crease_off_rest_max_deg']:.1f} "
            "deg at most." for h, code, wall, s, err, _ in rows if s is not None and "crease_edges" in s["garment"]]
    levels = [(h, s["garment"]["closing_levels"]) for h, code, wall, s, err, _ in rows
              if s is not None and len(s["garment"].get("closing_levels", [])) > 1]
    if levels:
        out += ["", "Closing on a coarser mesh (`garment.closing_h`), each level:", "",
                "| h [cm] | level h [cm] | nodes | mean element [cm] | gap start / end [cm] | simulated [s] | steps | "
                "wall [s] |", "|---|---|---|---|---|---|---|---|"]
        out += [f"| {h:g} | {r['h']:g} | {r['nodes']} | {r['mean_element_size']:.2f} | "
                f"{r['largest_seam_gap_start']:.3f} / {r['largest_seam_gap']:.3f} | {r['time']:.2f} | {r['steps']} | "
                f"{r['wall_time']:.0f} |" for h, rs in levels for r in rs]
    return out


FRICTION = 0.3
"""Coulomb coefficient of the friction row (garment on form)."""
FRICTION_H = 3.0
"""Element size [cm] of the friction rows."""

SCENES = (
    ("skirt-a-line", "a_line_h", "## The A-line skirt (two panels, two side seams)",
     "`cases/skirt-a-line.toml`: the two-panel A-line skirt of `cases/patterns/skirt-a-line.toml` (waist 72 cm, "
     "100 cm 18 cm below the waist, hem 165 cm, length 60 cm; front and back placed 18 cm before and behind the "
     "form's axis), the seams closed on a 5 cm mesh and carried to the garment's mesh (`garment.closing_h`)."),
    ("skirt-a-line-hem", "hem_h", "## The A-line skirt with its hem turned up (fold seams)",
     "`cases/skirt-a-line-hem.toml`: `skirt-a-line` with a 4 cm hem turned up inside "
     "(`cases/patterns/skirt-a-line-hem.toml`): each panel's hem is a `fold` seam with a facing placed turned up "
     "behind it, held at 180 deg by the crease's hinges (`rftstatic.element.hinge`), the facings sewn at the sides; "
     "self-contact keeps the facing off the skirt. The hem is the crease (the facings left out of the hem measures); "
     "`crease off rest`: the creases' largest distance from 180 deg at the end."),
    ("skirt-circle", "circle_h", "## The circle skirt (one ring panel, no seams)",
     "`cases/skirt-circle.toml`: a full circle skirt cut as one ring (waist girth 70 cm, length 50 cm) placed flat "
     "at the waist; no seams, so no closing: the static solve from the flat ring, its rotation about the vertical "
     "held at one waist node."),
    ("dress", "dress_h", "## The dress (four panels, six seams)",
     "`cases/dress.toml`: the sleeveless shift dress of `cases/patterns/dress-shift.toml` (front, back and two side "
     "panels; four side seams and two shoulder seams; bust 98, hip 104, hem 108 cm; hem 55 cm above the floor as "
     "placed), the seams closed on a 3 cm mesh and carried to the garment's mesh; it hangs from its shoulder seams "
     "and neckline on the form's shoulders."),
)
"""(scene, option, heading, description) of each section."""


def _verdict(name, done) -> list:
    if len(done) < 2:
        return [f"- {name}: fewer than two meshes ran: no convergence check."]
    (h0, *_, s0, _, _), (h1, *_, s1, _, _) = done[-2], done[-1]
    f0, f1 = s0["garment"]["hem_folds"], s1["garment"]["hem_folds"]
    d0, d1 = s0["garment"]["hem_drape_coefficient"], s1["garment"]["hem_drape_coefficient"]
    m0 = s0["garment"]["mean_element_size"]
    differ = ("the routes' drapes differ: each mesh's drape carried to the others below"
              if name in CARRIED else "not converged")
    return [f"- {name}: mean element {m0:.2f} cm ({'<=' if m0 <= 1.5 else '>'} 1.5 cm); hem folds {f0} at h = {h0:g} "
            f"cm against {f1} at h = {h1:g} cm ({'the same' if f0 == f1 else differ}); hem DC {d0:.4f} "
            f"against {d1:.4f} ({abs(d0 - d1) / d1 * 100:.1f} % apart)."]


CARRIED = ("skirt-circle",)
"""Scenes whose drapes are carried between the report's meshes (:func:`_carried`): those whose fold counts differ."""


def _carried(scene, runs, work, extra=()) -> list:
    """Each finished run of ``scene`` carried to the other mesh sizes of its table and to the sizes ``extra`` (no run
    of their own) and solved there by Newton (:func:`rftstatic.app.garment_carry.carry_drape`; kept as JSON in
    ``work`` for ``--reuse``): rows ``(source h, target h, table)``."""
    from rftstatic import api
    from rftstatic.app.garment_carry import carry_drape

    done = [r[0] for r in runs if r[3] is not None]
    rows = []
    for hs in done:
        for hd in [*done, *extra]:
            if hs == hd:
                continue
            name = work / f"carry-{scene}-{hs:g}-to-{hd:g}"
            kept = name.with_suffix(".json")
            if REUSE and kept.is_file():
                table = json.loads(kept.read_text())
            else:
                table = carry_drape(api.load_scene(scene), work / f"{scene}-{hs:g}", hs, out=name, h=hd)
                kept.write_text(json.dumps(table, indent=1))
            rows.append((hs, hd, table))
            print(f"{scene} carried {hs:g} -> {hd:g}: {table['hem_folds']} folds, {table['wall_time_s']:.0f} s",
                  flush=True)
    return rows


def _carry_section(scene, runs, carried) -> tuple[list, list]:
    """The drapes of ``scene`` found on each mesh, each also solved on the other meshes: (section lines, verdict)."""
    lines = [f"## The {scene} drapes on each mesh", "",
             "Which of several near-equal stable drapes the route finds depends on the fall from the flat start, so the "
             "fold counts of two meshes' own runs mix the mesh with the route. Here each mesh's drape is also carried to "
             "the other mesh through the flat pattern and solved there by Newton at full load "
             "(`rftstatic.app.garment_carry.carry_drape`): a drape that is a stable minimum with the same folds on "
             "both meshes is resolved by both; the energies of two drapes on one mesh say which is lower there.", "",
             "| mesh h [cm] | drape found by the route on | converged | stable | hem folds | hem DC | total energy "
             "[gf cm] | Newton its | wall [s] |", "|---|---|---|---|---|---|---|---|---|"]
    best, rows = {}, []
    for h, code, wall, s, err, figures in runs:
        if s is None:
            continue
        e = s["energies"]["total"]
        rows.append((-h, 0, f"| {h:g} | {h:g} (its own run) | {s['converged']} | {s['stable_minimum']} | "
                     f"{s['garment']['hem_folds']} | {s['garment']['hem_drape_coefficient']:.4f} | {e:.3f} | "
                     f"{s['newton_iterations']} | {_wall(wall, figures)} |"))
        best.setdefault(h, []).append((e, s["garment"]["hem_folds"], s["stable_minimum"]))
    for hs, hd, t in carried:
        e = t["energies"]["total"]
        rows.append((-hd, -hs, f"| {hd:g} | {hs:g} (carried: {t['nodes']} nodes) | {t['converged']} | "
                     f"{t['stable_minimum']} | {t['hem_folds']} | {t['hem_drape_coefficient']:.4f} | {e:.3f} | "
                     f"{t['newton_iterations']} | {t['wall_time_s']:.0f} |"))
        best.setdefault(hd, []).append((e, t["hem_folds"], t["stable_minimum"] and t["converged"]))
    lines += [r[2] for r in sorted(rows)]
    verdict = []
    own = {h: (s["garment"]["hem_folds"], s["garment"]["hem_drape_coefficient"]) for h, _, _, s, *_ in runs
           if s is not None}
    for hs, (folds, dc) in own.items():  # each drape on every mesh: its folds, and its DC's convergence
        on = sorted([(hs, folds, dc)] + [(hd, t["hem_folds"], t["hem_drape_coefficient"]) for h0, hd, t in carried
                                         if h0 == hs], reverse=True)
        text = (f"the drape of the {hs:g} cm run ({folds} folds) has " + ", ".join(f"{f} folds, DC {d:.4f} at "
                f"{h:g} cm" for h, f, d in on))
        if len(on) >= 3:
            (h0, _, d0), (h1, _, d1), (h2, _, d2) = on[-3:]
            if (d0 - d1) * (d1 - d2) > 0 and abs(d1 - d2) > 0:
                rate = np.log(abs(d0 - d1) / abs(d1 - d2)) / np.log(h0 / h1)
                text += f" (the DC's observed rate {rate:.2f} over the last three meshes)"
        verdict.append(text)
    for h, rows in sorted(best.items(), reverse=True):
        held = sorted({f for _, f, ok in rows if ok})
        low = min((r for r in rows if r[2]), default=None)
        spread = max(r[0] for r in rows) - min(r[0] for r in rows)
        verdict.append(f"on the {h:g} cm mesh stable drapes of {' and '.join(map(str, held))} folds"
                       + (f", the lowest in energy {low[1]} folds ({spread:.3g} gf cm apart, "
                          f"{spread / abs(low[0]):.1e} relative)" if low is not None and len(rows) > 1 else ""))
    return lines, [f"- {scene}'s drapes carried between the meshes: " + "; ".join(verdict) + "."]


def _run_cusick(out):
    """The Cusick test of the circle skirt's fabric (``case cusick-30``, the same preset): (exit, wall, summary)."""
    t = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "rftstatic", "case", "cusick-30", "--no-figures", "--out", str(out)],
                       capture_output=True, text=True, cwd=ROOT)
    wall = time.perf_counter() - t
    return p.returncode, wall, json.loads((out / "summary.json").read_text()) if p.returncode == 0 else None


def _cusick_section(circle, cusick) -> list:
    """The circle skirt's hem node count beside the Cusick node count of its fabric (both simulated here)."""
    code, wall, s = cusick
    lines = ["## The circle skirt's node count against its fabric's Cusick test", "",
             "Both simulated here with the same fabric (`wool-kang-yu`): `cusick-30` (30 cm specimen on the 18 cm disc, "
             "its default route) and the circle skirt on the form. Published studies compare a circle skirt's node "
             "count with the fabric's Cusick count; no such table with this fabric's data was found (see "
             "[measured_drape.md](measured_drape.md) for the literature searched), so the comparison is between the two "
             "simulations only.", "",
             "| run | nodes (folds) | drape coefficient | wall [s] |", "|---|---|---|---|"]
    if s is None:
        return lines + [f"| cusick-30 | exit {code} | | {wall:.0f} |"]
    lines.append(f"| cusick-30 | {s['drape']['fold_count']} | {s['drape']['drape_coefficient']:.4f} (Cusick DC) | "
                 f"{wall:.0f} |")
    lines += [f"| skirt-circle h = {h:g} cm | {r['garment']['hem_folds']} | {r['garment']['hem_drape_coefficient']:.4f} "
              f"(hem shadow over flat area) | {_wall(w, figures)} |" for h, code, w, r, err, figures in circle
              if r is not None]
    return lines


def _fabric_material(row) -> str:
    """``--set`` value of a transcribed fabric's KES data as the scene's whole ``[material]`` (one B for both)."""
    b = row["B_gf*cm^2/cm"]
    return (f"material={{kes_B_warp={b}, kes_B_weft={b}, kes_W={row['W_mg/cm^2']}, kes_T={row['T_mm']}}}")


def _fabric_run(work, row, scene, sets, tag=""):
    """One run of a transcribed fabric (``--no-figures``): ``(summary or None, wall [s], the error line or "")``."""
    out = work / f"fabric-{row['id']}-{scene}{tag}"
    if REUSE and (out / "summary.json").is_file() and json.loads((out / "summary.json").read_text())["converged"]:
        wall = json.loads((out / WALL_FILE).read_text())["wall_s"] if (out / WALL_FILE).is_file() else np.nan
        return json.loads((out / "summary.json").read_text()), wall, ""
    t = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "rftstatic", "case", scene, "--no-figures", "--out", str(out)]
                       + [a for k in sets for a in ("--set", k)], capture_output=True, text=True, cwd=ROOT,
                       timeout=TIMEOUT)
    wall = time.perf_counter() - t
    if p.returncode == 0:
        (out / WALL_FILE).write_text(json.dumps({"wall_s": wall, "figures": False}))
    print(f"fabric {row['id']} {scene}{tag}: exit {p.returncode}, {wall:.0f} s", flush=True)
    error = next((line for line in p.stderr.splitlines() if line.startswith("error:")), "")
    return (json.loads((out / "summary.json").read_text()) if p.returncode == 0 else None), wall, error


def _skirt_cells(run) -> tuple[str, str]:
    """The hem DC and folds, and converged / stable / crossings form, self, of a skirt run (or why it failed)."""
    import re

    k, _, error = run
    if k is None:
        fell = re.search(r"the sheet fell: .*? s(?=: nothing holds it)", error)
        return ("slid off the form", fell.group(0)) if fell else ("failed", error[:120])
    return (f"{k['garment']['hem_drape_coefficient']:.4f}, {k['garment']['hem_folds']}",
            f"{k['converged']}, {k['stable_minimum']}, {k['garment']['body_crossing_pairs']} / "
            f"{k['self_intersections']['pairs']}")


def _fabric_section(work) -> list:
    """The circle skirt (frictionless as the scene stands, and with ``contact.friction`` = :data:`FRICTION`) and the
    Cusick test (both simulated) of the four fabrics of Matsudaira et al. (2015) as transcribed second-hand, beside
    their measured Cusick DC and node count."""
    from rftstatic.references.drape_literature import secondary_table

    lines = ["## Four transcribed fabrics: circle skirt against Cusick test", "",
             "The four fabrics of Matsudaira, Masuda, Wada & Yokura (2015), *Shape factor of flared skirts compared "
             "with that of circular fabrics*, as a third party transcribed their KES data and measured Cusick DC and "
             "node count (`rftstatic.references.drape_literature.secondary_table`; the paper itself and its skirt "
             "measurements were not within reach), each given by its KES values alone to `cusick-30` (its default "
             "route) and to `skirt-circle` (its mesh), frictionless as the scene stands and with `contact.friction = "
             f"{FRICTION}` (garment on form): the simulated skirt's hem folds against the simulated and the measured "
             "Cusick node count of the same fabric. On the frictionless form the skirt's 70 cm waist ring slides down "
             "the waist-to-hip flare until its hoop tension holds it (the wool's at 88 cm, 12 cm below the form's "
             "waist, stretched 25 %); a limp, light fabric's ring stretches over the 92 cm hips and the skirt slides "
             "off: the relaxation stops when its mass centre is three of its diagonals below where it was placed "
             "(`rftstatic.solvers.relaxation.FALL_DIAGONALS`), exit 3 naming the fall.", "",
             "| fabric | measured Cusick DC [%], nodes | cusick-30 DC [%], nodes | skirt-circle hem DC, folds | "
             "converged, stable, crossings form / self | with friction: hem DC, folds | converged, stable, crossings |"
             " wall cusick / skirt / with friction [s] |", "|---|---|---|---|---|---|---|---|"]
    for row in secondary_table():
        sets = [_fabric_material(row)]
        cusick = _fabric_run(work, row, "cusick-30", sets)
        skirt = _fabric_run(work, row, "skirt-circle", sets)
        held = _fabric_run(work, row, "skirt-circle", sets + [f"contact.friction={FRICTION}"], f"-mu{FRICTION}")
        c = cusick[0]
        cus = f"{c['drape']['drape_coefficient_percent']:.1f}, {c['drape']['fold_count']}" if c else "failed"
        lines.append(f"| {row['id']} {row['name']} (B {row['B_gf*cm^2/cm']}, W {row['W_mg/cm^2']}) | {row['DC_pub_%']}, "
                     f"{row['nodes_pub']} | {cus} | {' | '.join(_skirt_cells(skirt))} | {' | '.join(_skirt_cells(held))}"
                     f" | {cusick[1]:.0f} / {skirt[1]:.0f} / {held[1]:.0f} |")
    return lines


def main(argv=None):
    global REUSE, TIMEOUT
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "validation"))
    ap.add_argument("--a-line-h", type=float, nargs="+", default=[1.45, 1.1])
    ap.add_argument("--hem-h", type=float, nargs="+", default=[3.0, 2.0])
    ap.add_argument("--circle-h", type=float, nargs="+", default=[1.48, 1.1])
    ap.add_argument("--dress-h", type=float, nargs="+", default=[1.1, 0.9])
    ap.add_argument("--carry-h", type=float, nargs="*", default=[0.8],
                    help="further meshes [cm] the circle skirt's drapes are carried to (no run of their own)")
    ap.add_argument("--no-fabrics", dest="fabrics", action="store_false",
                    help="leave out the four transcribed fabrics' circle skirts and Cusick tests")
    ap.add_argument("--work", default="/tmp/garment-report")
    ap.add_argument("--reuse", action="store_true", help="reuse finished runs in --work (module docstring)")
    ap.add_argument("--timeout", type=float, default=TIMEOUT, help="longest run (or wait for one under way) [s]")
    a = ap.parse_args(argv)
    REUSE, TIMEOUT = a.reuse, a.timeout
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    results = {scene: [None] * len(getattr(a, option)) for scene, option, *_ in SCENES}
    for k in (0, 1):  # every scene as it stands (timed with figures) first, then the finer meshes
        for scene, option, *_ in SCENES:
            for j, h in enumerate(getattr(a, option)):
                if (j == 0) != (k == 0):
                    continue
                code, wall, s, err = _run(scene, h, work / f"{scene}-{h:g}", figures=j == 0)
                results[scene][j] = (h, code, wall, s, err, j == 0)
                print(f"{scene} h {h}: exit {code}, {wall:.0f} s", flush=True)
    friction = []
    for mu in (0.0, FRICTION):
        code, wall, s, err = _run("skirt-a-line", FRICTION_H, work / f"skirt-a-line-mu{mu:g}", False,
                                  [f"contact.friction={mu}"])
        friction.append((FRICTION_H, code, wall, s, err, False))
        print(f"skirt-a-line mu {mu}: exit {code}, {wall:.0f} s", flush=True)
    cusick = _run_cusick(work / "cusick-30")
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT).stdout.strip()
    load = " ".join(f"{v:.2f}" for v in os.getloadavg())
    lines = [
        "# Garments: skirts and a dress sewn from panels on the dress form",
        "",
        f"Generated by `python tools/garment_report.py` at commit {commit} "
        f"({time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
        f"{platform.node()}, {os.cpu_count()} cores, load average at the end {load}: the machine was shared, so "
        "wall times are single runs under that load).",
        "",
        "Every garment on a size-36 dress form (bust 84, waist 66, hip 92 cm), wool (`wool-kang-yu`), RFT6, "
        "frictionless. The seams are pulled shut by seam springs in damped explicit runs without gravity, merged, "
        "and the sewn garment is draped under gravity by the relaxation route and Newton (`rftstatic.app.garment`, "
        "`docs/howto/garments.md`). The first row of each table is the scene as it stands, the whole `case` "
        "command with its figures; the second a finer mesh (`--no-figures`) for the fold count's convergence.",
        "",
        "Independent checks: the crossing test of the garment's triangles against the form's own surface "
        "(`body.obj`; the contact surface lies `contact clearance` outside it), the self-intersection test, the "
        "stability of the equilibrium (the tangent's inertia), the seam gap measured on the node pairs before the "
        "merge. The hem's folds are the node count of its outline seen from above about the form's axis, as for a "
        "Cusick specimen. Hem DC: the shadow of the draped garment over its flat area.",
    ]
    for scene, _, heading, text in SCENES:
        lines += ["", heading, "", text, "", *_table(results[scene])]
    lines += ["", "## Friction between garment and form", "",
              f"`skirt-a-line` at h = {FRICTION_H:g} cm, frictionless (first row) and with `contact.friction = "
              f"{FRICTION}` (second row; Coulomb, static = kinetic): the closing's explicit runs with friction "
              "impulses, the static solve with lagged friction and stick anchors (`rftstatic.contact.friction`).", "",
              *_table(friction)]
    lines += ["", *_cusick_section(results["skirt-circle"], cusick)]
    if a.fabrics:
        lines += ["", *_fabric_section(work)]
    verdict = []
    for scene, *_ in SCENES:
        verdict += _verdict(scene, [r for r in results[scene] if r[3] is not None])
    for scene in CARRIED:
        section, said = _carry_section(scene, results[scene], _carried(scene, results[scene], work, a.carry_h))
        lines += ["", *section]
        verdict += said
    done = [r for rows in results.values() for r in rows if r[3] is not None]
    stable = all(r[3]["converged"] and r[3]["stable_minimum"] for r in done)
    verdict += [
        f"- Runs that ended with a drape: {len(done)} of {sum(len(r) for r in results.values())}. Crossing pairs with "
        f"the form: {', '.join(str(r[3]['garment']['body_crossing_pairs']) for r in done)}; self-intersections: "
        f"{', '.join(str(r[3]['self_intersections']['pairs']) for r in done)}; every run "
        f"{'converged to a stable minimum' if stable else 'NOT all converged and stable'}.",
        "- Whole `case` commands with figures: " + ", ".join(
            f"{scene} {_wall(rows[0][2], True)} s" for scene, rows in results.items() if rows) + " (issue 37: skirt-circle under "
        "120 s, dress under 900 s, on an idle machine).",
        "- Not met yet (issue 37): the circle skirt's node count "
        "against a published comparison: Matsudaira, Masuda, Wada & Yokura (2015), J. Textile Eng. 61(6) 69-73, "
        "compare flared skirts with circular specimens of the same fabrics, but only its abstract and a partial "
        "second-hand transcription of its fabric table were reachable (`rftstatic.references.drape_literature`), so "
        "the comparison above is between the two simulations; the verdicts above for the rest.",
    ]
    lines += ["", "## Verdict", "", *verdict, ""]
    Path(a.out, "garments.md").write_text("\n".join(lines), encoding="utf-8")
    print(f"wrote {Path(a.out, 'garments.md')}")


if __name__ == "__main__":
    main()
