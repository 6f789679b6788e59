"""Scenes the property test (tests/app/test_scene_property.py) found mishandled: each is now an input error
(exit 2) of one line that names the scene file and the key."""

import pytest

from rftstatic.cli import main


def _run(capsys, tmp_path, scene, sets=(), text=None):
    """Exit status and stderr of ``case SCENE --set ...`` (``text``: a scene file of that content)."""
    if text is not None:
        scene = tmp_path / "scene.toml"
        scene.write_text(text)
    argv = ["case", str(scene), *(a for kv in sets for a in ("--set", kv)), "--out", str(tmp_path / "o"),
            "--no-figures"]
    code = main(argv)
    return code, capsys.readouterr().err.strip()


def _assert_input_error(code, err, key, fragment):
    assert code == 2, err
    assert "\n" not in err and "Traceback" not in err, err
    assert f": {key}: " in err and fragment in err, err


@pytest.mark.parametrize("sets, key, fragment", [
    # was: internal error: KeyError: 'nu' (an isotropic shell's key next to a fabric preset)
    (["material.nu=-1e-05"], "material.nu", 'does not apply next to preset = "wool-kang-yu"'),
    (["material.E=1e6"], "material.E", "does not apply next to preset"),
    # a mesh too big to build: was a MemoryError (an internal error) or a run that never ends
    (["mesh.nodes=[100000000,1000000]"], "mesh.nodes", "more than 2,000,000"),
    (["solver.relax_damping=firee"], "solver.relax_damping", 'is not one of viscous, fire, kinetic, viscous-fire (did'),
])
def test_strip_mutations_are_input_errors(capsys, tmp_path, sets, key, fragment):
    _assert_input_error(*_run(capsys, tmp_path, "strip", sets), key, fragment)


@pytest.mark.parametrize("mesh, key, fragment", [
    # was: "error: the smallest target size 0.167 m exceeds the domain's width 0.01 m" (no file, no key)
    ("h = 16.7", "mesh.h", "is larger than the sheet (1 across"),
    ("h = 1e-300", "mesh.h", "would give countless nodes"),
    ("h = 1e-4\nsize = [50.0, 50.0]", "mesh.h", "would give about 2.89e+11 nodes"),
    ("h = -1.0", "mesh.h", "must be > 0"),
    ("h = 1.0\nsize = [-5.0, 5.0]", "mesh.size", "both sides must be > 0"),
    ("h = 1.0\nradius = 0.0", "mesh.radius", "must be > 0"),
])
def test_bad_unstructured_sizes_are_input_errors(capsys, tmp_path, mesh, key, fragment):
    text = f'[mesh]\nkind = "unstructured"\n{mesh}\n[[supports]]\nkind = "pinned"\nat = [0.0, 0.0]\n'
    _assert_input_error(*_run(capsys, tmp_path, None, text=text), key, fragment)


def test_a_negative_seed_is_an_input_error(capsys, tmp_path):
    # was: internal error: ValueError: expected non-negative integer (numpy's generator, deep in the solver)
    code, err = _run(capsys, tmp_path, "strip", ["mesh.nodes=[5,3]", "solver.seed=-100000000000",
                                                  "solver.perturbation=0.01"])
    _assert_input_error(code, err, "solver.seed", "is out of range: must be in [0, 4,294,967,295]")


@pytest.mark.parametrize("scene, obstacle", [("pedestal-square-20", "half_width=1e300"),
                                             ("pedestal-round-50", "radius=1e300")])
def test_a_huge_pedestal_is_an_input_error(capsys, tmp_path, scene, obstacle):
    # was: RuntimeWarning: overflow in the footprint's area (an error under the test suite's warning filter); then
    # a run that ended (exit 0 or 3) on a pedestal 1e300 wide. Now beyond 1000 sheet sizes is refused.
    nodes = "[5,5]" if scene == "pedestal-square-20" else "[3,8]"
    code, err = _run(capsys, tmp_path, scene, [f"mesh.nodes={nodes}", f"obstacles.0.{obstacle}"])
    key = obstacle.split("=")[0]
    _assert_input_error(code, err, f"obstacles.0.{key}", "1e+300 must be 0 (where the obstacle takes it) or lie in")
    assert "1000 sheet sizes (a larger one is a plane: use a floor)" in err, err


@pytest.mark.parametrize("pattern", ["RIGHT", "union-jack"])
def test_an_unknown_square_polar_pattern_is_an_input_error(capsys, tmp_path, pattern):
    # was: accepted silently, and meshed as "left"
    code, err = _run(capsys, tmp_path, "pedestal-round-50", ["mesh.nodes=[2,17]", f"mesh.pattern={pattern}"])
    _assert_input_error(code, err, "mesh", f'unknown diagonal pattern "{pattern}" for a square-polar mesh')


REMESH_TINY = ["mesh.h=4.0", "remesh.h_lower=5.0", "remesh.h_upper=8.0", "remesh.const=5.0", "dynamics.t_end=0.1",
               "dynamics.frames=[0.1]"]


def test_a_remeshed_relaxation_keeps_to_max_steps(capsys, tmp_path):
    import json

    # was: dynamics.max_steps ignored by the remeshed relaxation (10^9 steps), a tiny scene ran for minutes
    code, err = _run(capsys, tmp_path, "remesh-pedestal-square-20", [*REMESH_TINY, "dynamics.mass_scale=1e-6",
                                                                      "dynamics.max_steps=1000"])
    _assert_input_error(code, err, "dynamics.t_end", "more than the limit of 1000 (dynamics.max_steps)")
    code, err = _run(capsys, tmp_path, "remesh-pedestal-square-20", [*REMESH_TINY, "dynamics.max_steps=100"])
    assert code == 3 and "within dynamics.max_steps = 100 explicit steps" in err, err
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["steps"] <= 200 and summary["stopped_by"] == "max_steps" and summary["converged"] is False


def test_a_remeshed_relaxation_that_blows_up_is_unstable_not_an_internal_error(capsys, tmp_path):
    # was: internal error: FloatingPointError: remesh_relax: non-finite state after step 200
    # (to t_end = 10 s: 200 steps; a run to 0.1 s is 2 steps, now that the last chunk ends at t_end)
    code, err = _run(capsys, tmp_path, "remesh-pedestal-square-20", [*REMESH_TINY, "dynamics.dt=0.05",
                                                                      "dynamics.t_end=10.0", "dynamics.frames=[10.0]"])
    assert code == 3 and err.startswith("error: the explicit run became unstable: the state became non-finite"), err


def test_a_remeshed_static_run_whose_mesh_still_changes_exits_3(capsys, tmp_path):
    # was: exit 0 with summary.json saying converged = false
    code, err = _run(capsys, tmp_path, "remesh-sphere-30", [*REMESH_TINY, "analysis=static", "remesh.max_cycles=0"])
    assert code == 3 and "the mesh still changed after remesh.max_cycles = 0" in err, err


def test_a_sheet_that_slides_off_the_sphere_gets_no_drape_measures(capsys, tmp_path):
    import json

    # was: internal error: ValueError: fold_count: the ray at 175.5 deg from centre = (0, 0) misses the boundary
    code, err = _run(capsys, tmp_path, "sphere-30", ["mesh.nodes=[5,4]"])
    assert code in (0, 3) and "internal error" not in err, err
    drape = json.loads((tmp_path / "o" / "summary.json").read_text())["drape"]
    assert drape["applicable"] is False and "does not surround the obstacle's centre" in drape["reason"]


@pytest.mark.parametrize("lift", ["1e4", "9223372036854775807", "-1"])
def test_a_perturbation_of_many_element_sizes_is_an_input_error(capsys, tmp_path, lift):
    # was: internal error: ValueError: t_end = 87.45 s with dt = 1.6e-22 s needs 5.41e+23 explicit steps (the
    # relaxation from the lifted start; solvers.static lets step_count's ValueError through)
    code, err = _run(capsys, tmp_path, "sphere-30", ["mesh.nodes=[3,14]", f"solver.perturbation={lift}"])
    _assert_input_error(code, err, "solver.perturbation", "is out of range: must be in [0, 10]")


@pytest.mark.parametrize("sets", [
    ["supports=[]"],  # was: 20 s of load steps and relaxation, then exit 3
    ["supports.0.kind=fixed", "supports.0.components=xy"],
])
def test_a_static_sheet_held_by_nothing_against_its_weight_is_an_input_error(capsys, tmp_path, sets):
    code, err = _run(capsys, tmp_path, "strip", ["mesh.nodes=[5,3]", *sets])
    _assert_input_error(code, err, "supports", "nothing holds the sheet along z")


def test_a_relaxation_start_without_mass_is_an_input_error(capsys, tmp_path):
    # was: internal error: ValueError: material 'wool-kang-yu (modified)' has mass_per_area = 0.0 kg/m^2
    code, err = _run(capsys, tmp_path, "pedestal-square-20", ["mesh.nodes=[5,5]", "material.weight=0.0"])
    _assert_input_error(code, err, "solver.start", "material.weight is 0")


def test_samples_beyond_a_thousand_are_an_input_error(capsys, tmp_path):
    # was: a tiny 1 ms run saving 3,000,000 states, past any time bound
    code, err = _run(capsys, tmp_path, "hang-20", ["mesh.nodes=[5,5]", "dynamics.t_end=0.001",
                                                   "dynamics.frames=[0.001]", "dynamics.samples=3000000"])
    _assert_input_error(code, err, "dynamics.samples", "3000000 is out of range: must be in [0, 1,000]")


@pytest.mark.parametrize("analysis", ["relax", "static"])
def test_a_remesh_h_lower_allowing_too_many_nodes_is_an_input_error(capsys, tmp_path, analysis):
    # was: a 37-node sheet remeshed to 67,430 nodes, then more: a run without end
    code, err = _run(capsys, tmp_path, "remesh-pedestal-square-20", [
        *REMESH_TINY, "remesh.h_lower=1e-3", "remesh.const=1e-3", f"analysis={analysis}"])
    _assert_input_error(code, err, "remesh.h_lower", "would let the remeshed sheet have up to 4.62e+08 nodes")


def test_a_relaxation_fallback_without_mass_is_a_reported_failure(capsys, tmp_path):
    # was: internal error: ValueError: material 'wool-kang-yu (modified)' has mass_per_area = 0.0 kg/m^2 (the
    # load steps failed and their relaxation fallback had no mass to move)
    code, err = _run(capsys, tmp_path, "strip", ["mesh.nodes=[5,3]", "material.weight=0.0", "loads.pressure=0.05",
                                                 "solver.max_iterations=1", "solver.max_load_steps=3"])
    assert code == 3 and "internal error" not in err, err
    assert "no dynamic relaxation: the material's areal weight is 0 N/m^2" in err, err


def test_a_lift_that_would_collapse_the_relaxation_step_is_refused_by_the_options():
    # was: ValueError from step_count (4.5e8 explicit steps of 1.9e-7 s) out of solve_static through the API;
    # the API's options now hold the range the scene key has
    from rftstatic.errors import ParameterError
    from rftstatic.solvers.static import StaticOptions

    with pytest.raises(ParameterError, match=r"solver\.perturbation: 10000\.0 is out of range: must be in \[0, 10\]"):
        StaticOptions.from_keys(start="relax", perturbation=1e4, progress=False)


def test_a_collapsed_explicit_step_is_a_step_limit_error():
    import numpy as np

    from rftstatic.errors import StepLimitError
    from rftstatic.solvers.step_plan import step_count

    for dt in (0.0, np.nan, -1.0, np.inf):
        with pytest.raises(StepLimitError, match="not a positive finite number"):
            step_count(1.0, dt)
    with pytest.raises(StepLimitError, match=r"more than the limit of 10 \(dynamics.max_steps\)"):
        step_count(1.0, 0.01, 10)


def test_a_relaxation_that_cannot_come_to_rest_stops_at_its_default_step_limit(capsys, tmp_path):
    import json
    import time

    # was: a default limit of 10^7 steps: a tiny undamped relaxation to t_end = 1e4 s ran for about 5 minutes
    t0 = time.perf_counter()
    code, err = _run(capsys, tmp_path, "hang-20", ["mesh.nodes=[5,5]", "analysis=relax", "dynamics.t_end=1e4",
                                                   "dynamics.alpha=0.0", "dynamics.frames=[]"])
    assert code == 3 and "did not come to rest within dynamics.max_steps = 50000 explicit steps" in err, err
    assert time.perf_counter() - t0 < 20
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["steps"] == 50000 and summary["stopped_by"] == "max_steps" and summary["converged"] is False


def test_the_default_step_limit_grows_with_the_nodes_along_a_side():
    from rftstatic.solvers.step_plan import MAX_STEPS, default_max_steps

    assert default_max_steps(25) == 50_000 and default_max_steps(41 * 41) == 410_000
    assert default_max_steps(1e15) == MAX_STEPS


def test_a_dynamic_run_beyond_the_default_step_limit_is_refused(capsys, tmp_path):
    code, err = _run(capsys, tmp_path, "hang-20", ["mesh.nodes=[7,7]", "dynamics.t_end=1e4", "dynamics.frames=[]"])
    _assert_input_error(code, err, "dynamics.t_end", "by default 10,000 x sqrt(nodes) = 70000 for 49 nodes")



def test_an_unloaded_relaxation_is_at_rest(capsys, tmp_path):
    import json

    # was: never at rest (the rest test needed a peak kinetic energy and a load to measure the force by)
    code, err = _run(capsys, tmp_path, "hang-20", ["mesh.nodes=[5,5]", "analysis=relax", "loads.gravity=false",
                                                   "dynamics.t_end=1.0", "dynamics.frames=[]"])
    assert code == 0, err
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["at_rest"] and summary["steps"] <= 1


def test_the_rest_test_of_a_perturbed_unloaded_sheet_measures_its_own_peak_force():
    from rftstatic.solvers.rest import AtRest, RestCriterion

    rest = AtRest(RestCriterion(1e-8, 1e-4), load_norm=0.0)
    assert rest(None, {"kinetic": 0.0, "residual": 0.0})  # no motion, no force: at rest
    rest = AtRest(RestCriterion(1e-8, 1e-4), load_norm=0.0)
    assert not rest(None, {"kinetic": 0.0, "residual": 1.0})  # a perturbed start
    assert not rest(None, {"kinetic": 1.0, "residual": 0.5})
    assert rest(None, {"kinetic": 1e-9, "residual": 1e-5})
    loaded = AtRest(RestCriterion(1e-8, 1e-4), load_norm=1.0)
    assert not loaded(None, {"kinetic": 0.0, "residual": 1.0})  # the first sample of a loaded sheet


@pytest.mark.parametrize("key, value", [("top", "-1e300"), ("top", "1e300"), ("centre", "[1e300, 0.0]")])
def test_an_obstacle_far_from_the_sheet_is_an_input_error(capsys, tmp_path, key, value):
    # was: RuntimeWarning: overflow encountered in multiply (an internal error under the warning filter)
    code, err = _run(capsys, tmp_path, "pedestal-square-20", ["mesh.nodes=[9,9]", f"obstacles.0.{key}={value}"])
    _assert_input_error(code, err, f"obstacles.0.{key}", "more than 1000 sheet sizes (20000 scene length units)")


def test_a_remeshed_relaxation_ends_at_t_end(capsys, tmp_path):
    import json

    # was: t = 0.58 s for t_end = 0.1 s (the stepper's whole chunk of 200 steps ran past t_end)
    code, err = _run(capsys, tmp_path, "remesh-pedestal-square-20", REMESH_TINY)
    assert code == 3 and "did not come to rest by t_end = 0.1 s" in err, err
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["t"] == pytest.approx(0.1, rel=1e-9) and summary["t"] <= 0.1 * (1 + 1e-12)
    assert summary["steps"] < 200


def test_an_unloaded_perturbed_sheet_on_a_pedestal_converges_by_load_steps(capsys, tmp_path):
    import json

    # was: exit 3, Newton stalled at |r| = 1.4e-9 N against the round-off floor (no load to scale the test by)
    code, err = _run(capsys, tmp_path, "pedestal-square-20", ["mesh.nodes=[9,9]", "loads.gravity=false",
                                                              "solver.start=load-steps"])
    assert code == 0, err
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["converged"] and summary["self_intersections"]["pairs"] == 0
    # the perturbed start relaxes back to a flat sheet (it floats where the penalty's onset left it, above the top)
    assert summary["max_relative_curvature"] < 1e-4
    heights = [p["deformed"][2] for p in summary["probes"].values()]
    assert min(heights) >= 0.0 and max(heights) - min(heights) < 1e-4


def test_the_convergence_scales_of_an_unloaded_model_are_its_weight():
    import numpy as np

    from rftstatic.bench.problems import strip_model
    from rftstatic.solvers.iteration import unloaded_scales

    model = strip_model(11, 3)
    force, work = unloaded_scales(model)
    expected = model.material.weight * np.linalg.norm(model.mesh.node_area)
    assert force == pytest.approx(expected) and work == pytest.approx(expected * model.mesh.element_size.mean())
    import dataclasses

    from rftstatic.model.model import Model

    weightless = Model(model.mesh, dataclasses.replace(model.material, weight=0.0), element=model.element,
                       supports=model.supports)
    assert unloaded_scales(weightless) == (1e-300, 1e-300)


def test_a_subnormal_time_step_is_an_input_error(capsys, tmp_path):
    # was: an OverflowError (checkpoint_every / dt), then a relaxation "at rest" after one step whose
    # velocity update had underflowed to zero
    code, err = _run(capsys, tmp_path, "pedestal-square-40", ["mesh.nodes=[14,3]", "analysis=relax", "dynamics.dt=5e-324",
                                                               "dynamics.t_end=0.01"])
    assert code == 2 and "dynamics.dt" in err and "stable step" in err, err


def test_checkpoint_steps_of_a_tiny_step_do_not_overflow():
    from rftstatic.app.dynamic import checkpoint_steps

    assert checkpoint_steps(0.2, 1e-3) == 200 and checkpoint_steps(0.2, 5e-324) == 10**12 and checkpoint_steps(1e-9, 1.0) == 1


def test_a_self_contact_thickness_above_a_quarter_of_h_lower_is_an_input_error(capsys, tmp_path):
    code, err = _run(capsys, tmp_path, "remesh-pedestal-square-20", ["contact.self=true", "contact.self_thickness=0.2"])
    assert code == 2 and "contact.self_thickness" in err and "remesh.h_lower" in err, err


@pytest.mark.parametrize("content", ["", "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n<Unstr"])
def test_an_empty_or_truncated_vtu_is_an_input_error_naming_the_scene(capsys, tmp_path, content):
    # was: exit 1 with meshio's own "Error: Couldn't read file ... as vtu" (its VTU reader calls sys.exit)
    path = tmp_path / "sheet.vtu"
    path.write_text(content)
    code, err = _run(capsys, tmp_path, "strip", ["mesh.kind=file", f"mesh.path={path}", "supports=[]"])
    assert code == 2 and "strip.toml" in err and "mesh" in err and "sheet.vtu" in err, err


SHELL = """units = "SI"
[mesh]
kind = "rectangle"
size = [1.0, 0.2]
nodes = [5, 3]
origin = [0.0, -0.1]
[material]
kind = "isotropic"
E = 1e6
nu = 0.3
thickness = 1e-3
weight = 1.0
[[supports]]
kind = "clamped"
box = [0.0, 0.0, -0.1, 0.1]
"""
"""An isotropic shell strip clamped at x = 0 (SI): issue 33's first input mutates its material."""


@pytest.mark.parametrize("line, key, fragment", [
    # was: internal error: OverflowError (E t^3 in rftstatic.material.isotropic_shell)
    ("thickness = 1e300", "material.thickness", "1e+300 must lie in (0, 1e+06] scene length units"),
    ("thickness = 5.0", "material.thickness", "to the sheet's smaller side (thicker is a block, not a shell)"),
    ("thickness = 1e-300", "material.thickness", "from 1e-06 mean element sizes"),
    ("E = 1e300", "material.E", "must lie in (0, 1e+13] (Young's modulus"),
    ("nu = 0.5", "material.nu", "must lie in (-1, 0.5)"),
])
def test_an_isotropic_shell_out_of_range_is_an_input_error(capsys, tmp_path, line, key, fragment):
    name = line.split(" = ")[0]
    text = "\n".join(line if row.startswith(f"{name} = ") else row for row in SHELL.splitlines())
    _assert_input_error(*_run(capsys, tmp_path, None, text=text), key, fragment)


HANG_TINY = ["mesh.nodes=[5,5]", "dynamics.t_end=0.01", "dynamics.frames=[0.01]"]


@pytest.mark.parametrize("scene, sets, key, fragment", [
    # was: internal error: OverflowError (the penalty's onset energy a^3 / (6 eps))
    ("pedestal-square-20", ["mesh.nodes=[5,5]", "contact.smoothing=1e300"], "contact.smoothing",
     "1e+300 is out of range: must be in [0, 1] (mean element sizes)"),
    # was: internal error: ValueError: smoothing must be a finite number >= 0 (PenaltyContact)
    ("pedestal-square-20", ["mesh.nodes=[5,5]", "contact.smoothing=-1"], "contact.smoothing",
     "-1 is out of range: must be in [0, 1] (mean element sizes)"),
    # was: internal error: ValueError: cannot convert float NaN to integer (the mesher's area estimate)
    ("pedestal-round-50", ["mesh.radius=1e300"], "mesh.radius",
     "the diameter (2 x radius) of the sheet must lie in [0.0001, 1e+08] (cm-gf-s length units"),
    # was: "the model has no stiffness on its free dofs" (exit 1), or 1e145 explicit steps refused (exit 3)
    ("sphere-30", ["mesh.nodes=[5,5]", "obstacles.0.radius=1e300"], "obstacles.0.radius",
     "to 1000 sheet sizes (a larger one is a plane: use a floor)"),
    # found by tests/app/test_scene_extremes.py: overflow in the distances to the clamping disc's centre
    ("cusick-30", ["mesh.nodes=[3,12]", "supports.0.centre=[1e300, 0.0]"], "supports.0.centre",
     "lies more than 1000 sheet sizes"),
    # found likewise: IndexError from the nearest-node search of a point at 1e300
    ("strip", ["mesh.nodes=[5,3]", "probes.0.at=[1e300, 0.0]"], "probes.0.at", "is not on the sheet"),
    ("pedestal-square-20", ["mesh.origin=[1e300, 0.0]"], "mesh.origin", "lies more than 1000 sheet sizes"),
    ("cusick-30", ["mesh.inner_radius=1e-300"], "mesh.inner_radius", "must be 0 (a full disc) or lie in"),
    ("cusick-30", ["mesh.nodes=[3,0]"], "mesh.nodes", "needs [n_radial, n_circ] of at least [2, 3]"),
    ("strip", ["mesh.nodes=[5,3]", "material.C_warp=-1"], "material.C_warp", "must be > 0 (a fabric's tensile"),
    # was: "dynamics.t_end: the explicit step dt = inf s (or 0.0 s) is not a positive finite number" (the wrong key)
    ("hang-20", [*HANG_TINY, "dynamics.alpha=1e300"], "dynamics.alpha", "1e+300 is out of range: must be in [0, 1e+06]"),
    ("hang-20", [*HANG_TINY, "dynamics.mass_scale=1e300"], "dynamics.mass_scale", "1e+300 is out of range: must be in [1e-06, 1e+06]"),
    ("hang-20", [*HANG_TINY, "material.weight=1e300"], "material.weight", "is heavier than 1.02e+04 (scene units"),
    # was: accepted, a warp 1e300 degrees from x (cos of it has no digit left)
    ("strip", ["mesh.nodes=[5,3]", "material.warp_angle=1e300"], "material.warp_angle", "must lie in [-360, 360] deg"),
])
def test_an_extreme_number_is_an_input_error(capsys, tmp_path, scene, sets, key, fragment):
    _assert_input_error(*_run(capsys, tmp_path, scene, sets), key, fragment)


@pytest.mark.parametrize("text, key", [
    ("x = " + "[" * 3000 + "]" * 3000 + "\n", "x"),  # was: internal error: RecursionError (tomllib)
    ("x = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n", "x"),
    ("[" + ".".join(["a"] * 3000) + "]\nb = 1\n", "a"),  # was: RecursionError in repr (the unknown key's message)
])
def test_a_deeply_nested_scene_is_an_input_error(capsys, tmp_path, text, key):
    code, err = _run(capsys, tmp_path, None, text=text)
    _assert_input_error(code, err, key, "nests tables or arrays")
    assert err.startswith(f"error: {tmp_path / 'scene.toml'}: {key}: "), err


def test_a_deeply_nested_override_is_an_input_error(capsys, tmp_path):
    code, err = _run(capsys, tmp_path, "strip", ["mesh.size=" + "[" * 3000 + "]" * 3000])
    assert code == 2 and err.startswith("error: --set mesh.size: the value nests arrays or tables"), err


def test_an_integer_beyond_64_bits_is_an_input_error(capsys, tmp_path):
    # was: internal error: OverflowError: int too large to convert to float (tomllib takes any integer)
    code, err = _run(capsys, tmp_path, "strip", ["mesh.nodes=[5,3]", f"mesh.size=[{10**400}, 1.0]"])
    _assert_input_error(code, err, "mesh.size", "an integer of 1329 bits is beyond TOML's 64-bit integers")


@pytest.mark.parametrize("where", ["file", "--set"])
def test_an_integer_of_5000_digits_is_an_input_error(capsys, tmp_path, where):
    # was: internal error: ValueError: Exceeds the limit (4300 digits) for integer string conversion (tomllib)
    if where == "file":
        code, err = _run(capsys, tmp_path, None, text=f"[mesh]\nz = {'9' * 5000}\n")
        assert err.startswith(f"error: {tmp_path / 'scene.toml'}: Exceeds the limit (4300 digits)"), err
    else:
        code, err = _run(capsys, tmp_path, "strip", [f"mesh.z={'9' * 5000}"])
        assert err.startswith("error: --set mesh.z: Exceeds the limit (4300 digits)"), err
    assert code == 2 and err.endswith("TOML's integers are 64-bit"), err


def test_a_rest_tolerance_of_one_or_more_is_an_input_error(capsys, tmp_path):
    # the kinetic-energy ratio of the at-rest test (rftstatic.solvers.rest) lies in (0, 1)
    code, err = _run(capsys, tmp_path, "hang-20", ["mesh.nodes=[5,5]", "dynamics.rest_tolerance=1.5"])
    _assert_input_error(code, err, "dynamics.rest_tolerance", "1.5 is out of range: must be in (0, 1)")


def test_a_refused_relaxation_names_the_keys_and_the_route_that_get_past_it(capsys, tmp_path):
    """A membrane far stiffer than the bending makes the relaxation route's explicit steps too many: exit 3, and
    the message says which route gets past it and that dynamics.max_steps does not."""
    code, err = _run(capsys, tmp_path, "strip", ["mesh.nodes=[11,3]", "solver.start=relax", "material.C_warp=1e9",
                                                  "material.C_weft=1e9"])
    assert code == 3, err
    assert "would need up to" in err and 'solver.start = "load-steps"' in err
    assert "dynamics.max_steps does not change" in err


def test_a_relaxation_segment_that_ends_before_rest_is_no_warning(caplog):
    """The static route relaxes on or hands over to Newton when a segment ends before rest: nothing for the user
    to do, so nothing at WARNING (it was printed three times on a run that then converged)."""
    from rftstatic.scenes.build import build_model
    from rftstatic.scenes.schema import load_scene
    from rftstatic.solvers.relaxation import RelaxOptions, relax

    model, _ = build_model(load_scene("strip", ["mesh.nodes=[11,3]"]))
    with caplog.at_level("INFO"):
        r = relax(model, RelaxOptions(alpha=1.0, max_time=1e-3, progress=False))
    assert not r.converged and "not at rest" in caplog.text
    assert not [rec for rec in caplog.records if rec.levelname == "WARNING" and "not at rest" in rec.message]


@pytest.mark.parametrize("sets", [
    ["mesh.nodes=[11,3]", "solver.max_load_steps=1", "solver.relax_fallback=false"],  # increments used up
    ["mesh.nodes=[11,3]", "solver.max_iterations=1", "solver.min_increment=0.05", "solver.relax_fallback=false"],
    ["mesh.nodes=[11,3]", "solver.start=relax", "material.C_warp=1e9", "material.C_weft=1e9"],  # refused relaxation
])
def test_an_unconverged_solve_says_what_to_try_last(capsys, tmp_path, sets):
    """Exit status 3: the message's last clause names a key or a route to try (issue 38, item 5)."""
    code, err = _run(capsys, tmp_path, "strip", sets)
    assert code == 3, err
    last = err.replace(". ", "; ").split("; ")[-1]
    assert any(word in last for word in ("solver.", "mesh", "material", "dynamics.")), err


def test_a_mesh_with_singular_patches_is_an_input_error_naming_the_scene(capsys, tmp_path):
    """A polar mesh too coarse for its patches (4 x 4 nodes on the Cusick annulus: the six points of 16 patches on
    one conic) is refused with the scene's file and its mesh key, not only the patch message."""
    assert main(["case", "cusick-30", "--set", "mesh.nodes=[4,4]", "--no-figures", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "cusick-30.toml: mesh: " in err and "singular patch" in err
