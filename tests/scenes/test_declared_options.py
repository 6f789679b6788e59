"""Options declared once (rftstatic.optionspec): the [solver] schema, the checks, the unit conversion and the
``options`` command all come from the same declarations, and disagree nowhere."""

import math

import pytest

from rftstatic.cli import main
from rftstatic.errors import ParameterError, SceneError
from rftstatic.optionspec import REQUIRED, declared, describe, from_table, option
from rftstatic.scenes.options import run_options, static_options
from rftstatic.scenes.run_options import SOLVER_GROUPS, RunOptions
from rftstatic.scenes.schema import SCHEMA, load_scene
from rftstatic.scenes.sections import SECTIONS, UNDECLARED, option_rows
from rftstatic.solvers.options import IncrementOptions, NewtonOptions, RouteOptions, StaticOptions


def _declared_keys(section=None):
    return [(sec, cls, name, spec, default) for sec, groups in SECTIONS.items() if section in (None, sec)
            for cls in groups for name, spec, default in declared(cls)]


def _required(cls) -> dict:
    """A valid value of each required option of ``cls`` (1 unit above its lower bound)."""
    return {name: (spec.low or 0) + 1 for name, spec, default in declared(cls) if default is REQUIRED}


@pytest.mark.parametrize("section", list(SECTIONS))
def test_each_key_is_declared_once_and_the_schema_and_listing_are_generated_from_it(section):
    names = [name for *_, name, spec, _ in _declared_keys(section) if spec.scene]
    assert len(names) == len(set(names)), f"a [{section}] key declared in two groups"
    assert set(SCHEMA[section][0]) == set(names) | set(UNDECLARED.get(section, ()))
    assert not set(names) & set(UNDECLARED.get(section, ()))
    assert [r["key"] for r in option_rows(section)] == [f"{section}.{n}" for n in names]
    for *_, name, spec, default in _declared_keys(section):
        assert spec.help and SCHEMA[section][0][name][1].startswith(spec.help)


def test_the_groups_are_split_by_concern_and_none_is_over_fifteen_fields():
    for cls in (*SOLVER_GROUPS, StaticOptions):
        assert len(cls.__dataclass_fields__) <= 15, cls.__name__
    assert {"rtol", "tangent", "step_solver"} <= {n for n, _, _ in declared(NewtonOptions)}
    assert {"initial_increment", "continuation"} <= {n for n, _, _ in declared(IncrementOptions)}
    assert {"start", "seed", "perturbation"} <= {n for n, _, _ in declared(RouteOptions)}
    assert {"levels", "seeds", "membrane", "compare"} == {n for n, _, _ in declared(RunOptions)} - {"level_membrane"}


@pytest.mark.parametrize("section, cls, name, spec, default",
                         [pytest.param(*k, id=f"{k[1].__name__}.{k[2]}") for k in _declared_keys()])
def test_every_declared_range_is_enforced_with_the_key_named(section, cls, name, spec, default):
    assert default is REQUIRED or spec.problem(default) is None  # the default lies in its own range
    bad = []
    if spec.kind in ("int", "float"):
        bad.append("seven" if not spec.nullable else [7])
        if spec.low is not None:
            bad.append(spec.low - (1 if spec.kind == "int" else abs(spec.low) * 0.5 + 1e-3))
        if spec.high is not None:
            bad.append(spec.high + (1 if spec.kind == "int" else abs(spec.high) + 1.0))
        if spec.kind == "float":
            bad += [math.nan, math.inf]
        else:
            bad += [1.5, True]
    elif spec.kind == "str":
        bad += ["no-such-choice", 3]
    else:
        bad.append(1)
    for value in bad:
        with pytest.raises(ParameterError, match=rf"^{section}\.{name}: "):
            cls(**{**_required(cls), name: value})


def test_a_scene_value_is_checked_in_the_scenes_units_and_converted_to_si():
    opts = static_options(load_scene("strip", ["solver.max_step=0.5", "solver.increment_displacement=2.0"]))
    assert opts.newton.max_step == pytest.approx(0.005) and opts.increments.increment_displacement == pytest.approx(0.02)
    with pytest.raises(SceneError, match=r"strip\.toml: solver\.max_step: -0\.5 is out of range: must be > 0"):
        static_options(load_scene("strip", ["solver.max_step=-0.5"]))
    auto = static_options(load_scene("strip", ['solver.max_step="auto"']))
    assert auto.newton.max_step is None


def test_flat_keys_reach_their_groups_and_an_unknown_one_is_named():
    opts = StaticOptions.from_keys(rtol=1e-9, start="relax", continuation="arc-length", progress=False)
    assert (opts.newton.rtol, opts.route.start, opts.increments.continuation, opts.progress) == \
        (1e-9, "relax", "arc-length", False)
    assert opts.replace(rtol=1e-3).newton.rtol == 1e-3 and opts.newton.rtol == 1e-9  # a copy
    with pytest.raises(ParameterError, match=r"solver\.rtoll: unknown option"):
        StaticOptions.from_keys(rtoll=1e-9)
    with pytest.raises(SceneError, match=r'solver\.rtoll: unknown key .*did you mean "solver\.rtol"'):
        load_scene("strip", ["solver.rtoll=1e-9"])


def test_an_angle_is_given_in_degrees_checked_in_degrees_and_held_in_radians():
    from rftstatic.scenes.options import cantilever_options

    opts = cantilever_options(load_scene("cantilever-warp", ["cantilever.angle=30"]))
    assert opts.angle == pytest.approx(math.pi / 6, rel=1e-15)
    with pytest.raises(SceneError, match=r"cantilever\.angle: 85 is out of range: must be in \[1, 80\]"):
        cantilever_options(load_scene("cantilever-warp", ["cantilever.angle=85"]))
    assert option_rows("cantilever")[0]["default"] == pytest.approx(41.5)


def test_the_app_keys_resolve_auto_levels():
    assert run_options(load_scene("strip")).levels == 1
    assert run_options(load_scene("strip", ["solver.levels=2"])).levels == 2
    with pytest.raises(SceneError, match=r"solver\.seeds: 0 is out of range"):
        run_options(load_scene("strip", ["solver.seeds=0"]))


def test_a_required_option_has_no_default_is_listed_as_required_and_named_when_missing():
    from rftstatic.remesh.options import RemeshOptions

    assert {n for n, _, d in declared(RemeshOptions) if d is REQUIRED} == {"const", "h_lower", "h_upper"}
    rows = {r["key"]: r for r in option_rows("remesh")}
    assert rows["remesh.const"]["default"] == "required" and rows["remesh.tol"]["default"] == 0.05
    assert SCHEMA["remesh"][0]["h_upper"][1].endswith("(required)")
    with pytest.raises(ParameterError, match=r"^remesh\.h_upper: is required: largest element size \[length\]"):
        from_table((RemeshOptions,), {"const": 1.0, "h_lower": 1.0}, "remesh")
    with pytest.raises(TypeError):
        RemeshOptions(const=1.0, h_lower=1.0)  # no default in Python either
    with pytest.raises(TypeError, match="needs its kind"):
        option(REQUIRED, "a required option without its type")


def test_a_remesh_table_is_converted_to_si_and_its_messages_quote_the_scene_units():
    from rftstatic.scenes.options import remesh_options

    base = ["remesh.const=0.5", "remesh.h_lower=0.25", "remesh.h_upper=2.0"]
    opts = remesh_options(load_scene("strip", [*base, "remesh.kappa_h2_max=0.1", 'remesh.kappa_h_max="auto"']))
    assert (opts.const, opts.h_lower, opts.h_upper) == pytest.approx((0.005, 0.0025, 0.02))  # cm -> m
    assert opts.kappa_h2_max == pytest.approx(0.001) and opts.kappa_h_max is None and opts.tol == 0.05
    with pytest.raises(SceneError, match=r"strip\.toml: remesh\.h_lower: -0\.25 is out of range: must be > 0"):
        remesh_options(load_scene("strip", [*base, "remesh.h_lower=-0.25"]))
    with pytest.raises(SceneError, match=r"remesh\.const: is required"):
        remesh_options(load_scene("strip", ["remesh.h_lower=0.25", "remesh.h_upper=2.0"]))


def test_an_option_default_outside_its_own_range_is_a_programming_error():
    with pytest.raises(TypeError, match="option default"):
        option(2.0, "a share", low=0.0, high=1.0)


@pytest.mark.parametrize("section", list(SECTIONS))
def test_the_options_command_lists_every_key_and_refuses_an_unknown_section(capsys, section):
    assert main(["options", section]) == 0
    out = capsys.readouterr().out
    for row in describe(SECTIONS[section], section):
        assert row["key"] in out
    assert main(["options", section, "--format", "markdown"]) == 0
    table = capsys.readouterr().out.splitlines()
    assert table[0].startswith("| key |") and len(table) == 2 + len(option_rows(section))
    assert all(line.count("|") == 7 for line in table)  # no cell breaks the table
    assert main(["options", "solverr"]) == 2
    err = capsys.readouterr().err
    assert 'no section "solverr"' in err and "known: solver" in err


def test_a_rate_is_converted_by_the_inverse_of_the_scenes_time_unit():
    from types import SimpleNamespace

    from rftstatic.optionspec import scene_factor, scene_values
    from rftstatic.scenes.dynamics_options import DynamicsOptions

    minutes = SimpleNamespace(time=60.0, length=1.0)
    assert scene_factor("rate", minutes) == pytest.approx(1 / 60) and scene_factor("time", minutes) == 60.0
    table = from_table((DynamicsOptions,), {"t_end": 2.0, "alpha": 6.0}, "dynamics", minutes)[DynamicsOptions]
    assert table == pytest.approx({"t_end": 120.0, "alpha": 0.1})  # 6 per minute = 0.1 /s
    assert scene_values(DynamicsOptions(**table), minutes)["alpha"] == pytest.approx(6.0)
    with pytest.raises(ParameterError, match=r"dynamics\.alpha: 100000000\.0 is out of range: must be in \[0, 6e\+07\]"):
        from_table((DynamicsOptions,), {"t_end": 2.0, "alpha": 1e8}, "dynamics", minutes)  # 1e6 /s, per minute


def test_the_dynamics_defaults_depend_on_the_analysis_and_frames_are_checked_against_t_end():
    from rftstatic.scenes.dynamics_options import DYNAMICS_DEFAULTS, DynamicsOptions
    from rftstatic.scenes.options import dynamics_options
    from rftstatic.solvers.rest import RELAX_MASS_SCALE, RELAX_REST

    tiny = ["mesh.nodes=[5,5]", "dynamics.frames=[0.5, 0.0, 0.5]", "dynamics.t_end=1.0"]
    dyn = dynamics_options(load_scene("hang-20", [*tiny, "dynamics.alpha=0.0"]))
    assert (dyn.t_end, dyn.alpha, dyn.mass_scale, dyn.samples) == (1.0, 0.0, 1.0, 30)
    assert dyn.rest_tolerance == {n: d for n, _, d in declared(DynamicsOptions)}["rest_tolerance"] == 1e-3
    assert list(dyn.frames) == [0.0, 0.005 * 100] and dyn.checkpoint_every == 0.2 and dyn.max_steps is None
    relax = dynamics_options(load_scene("pedestal-square-20", ["analysis=relax", "dynamics.t_end=1.0"]))
    assert (relax.alpha, relax.mass_scale, relax.rest_tolerance) == (5.0, RELAX_MASS_SCALE, RELAX_REST.tol_kinetic)
    given = dynamics_options(load_scene("pedestal-square-20", ["analysis=relax", "dynamics.t_end=1.0",
                                                               "dynamics.alpha=3.0", "dynamics.mass_scale=10.0"]))
    assert (given.alpha, given.mass_scale) == (3.0, 10.0)
    assert set(DYNAMICS_DEFAULTS["relax"]) <= {n for n, _, _ in declared(DynamicsOptions)}
    with pytest.raises(SceneError, match=r"dynamics\.frames: expected times in \[0, t_end = 1\.0\], got \[2\.0\]"):
        dynamics_options(load_scene("hang-20", [*tiny, "dynamics.frames=[2.0]"]))
    with pytest.raises(SceneError, match=r"hang-20\.toml: dynamics\.max_steps: 0 is out of range: must be >= 1"):
        dynamics_options(load_scene("hang-20", [*tiny, "dynamics.max_steps=0"]))
    with pytest.raises(SceneError, match=r'dynamics\.t_end: an analysis = "relax" scene needs its end time'):
        dynamics_options(load_scene("pedestal-square-20", ["analysis=relax"]))
    assert dynamics_options(load_scene("hang-20", [*tiny, 'dynamics.max_steps="auto"'])).step_limit(49) == 70_000


def test_a_contact_penalty_is_auto_or_a_stiffness_in_the_scenes_units():
    from rftstatic.scenes.build import build_model
    from rftstatic.scenes.options import contact_options

    assert contact_options(load_scene("pedestal-square-20")).penalty is None  # "auto" by default
    given = load_scene("pedestal-square-20", ["mesh.nodes=[5,5]", "contact.penalty=2.0"])
    units = given.units
    assert contact_options(given).penalty == pytest.approx(2.0 * units.force / units.length ** 3)
    model, _ = build_model(given)
    assert model.contact.stiffness == pytest.approx(contact_options(given).penalty)
    assert model.contact.smoothing == pytest.approx(0.05 * model.mesh.element_size.mean())
    for bad, why in (('"stiff"', r'must be a number or "auto", got \'stiff\''), ("0.0", "0.0 is out of range: must be > 0")):
        with pytest.raises(SceneError, match=rf"contact\.penalty: {why}"):
            contact_options(load_scene("pedestal-square-20", [f"contact.penalty={bad}"]))
    rows = {r["key"]: r for r in option_rows("contact")}
    assert rows["contact.penalty"]["unit"] == "force/length^3" and rows["contact.penalty"]["default"] == "auto"
    assert rows["contact.smoothing"]["unit"] == "mean element sizes"


def test_an_undeclared_unit_is_a_programming_error():
    with pytest.raises(TypeError, match='option unit "furlong"'):
        option(1.0, "a distance", unit="furlong")



def test_a_static_drape_names_a_dynamics_table_it_does_not_read(tmp_path, caplog):
    from rftstatic.cli import main

    with caplog.at_level("WARNING", logger="rftstatic.scenes.options"):
        assert main(["case", "strip", "--no-figures", "--out", str(tmp_path / "run"), "--set", "dynamics.alpha=3"]) == 0
    assert "strip.toml: [dynamics] is not read by a static drape" in caplog.text and "remove it" in caplog.text
