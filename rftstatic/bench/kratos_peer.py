"""Peer code for the clamped-strip benchmark: the §4.1 wool strip solved with Kratos Multiphysics.

``python -m rftstatic.bench.kratos_peer NX NY [INCREMENTS]`` solves the strip of
:func:`rftstatic.bench.problems.strip_model` (5 x 1 cm, clamped along x = 0, own weight along -z,
``NX`` nodes along the length, ``NY`` across) with Kratos's general shell element and prints
the result of :func:`solve_strip` as JSON, so a bench can run it as a child process beside
rftstatic's Newton solver. Reference: the heavy elastica (Sze & Zhou 2016 §4.1), tip drop
4.34468 cm at the mid-width point of the free end (x = L, y = 0).

Material mapping. Kratos has no fabric law, so the strip is an isotropic linear-elastic thin
shell with the warp rigidities of Kang & Yu's wool (B = 0.083 gf cm, C = 1118.2 gf/cm, weight
w = 0.019 gf/cm^2, all from ``preset("wool-kang-yu")`` in SI):

    nu = 0,   t = sqrt(12 B / C),   E = C / t     (so E t = C and E t^3 / 12 = B),
    rho = w / (t g),   g = 9.80665 m/s^2           (so rho t g = w).

With nu = 0 the strip bends along x with B and stretches with C as in the beam reference; the
weft and shear rigidities of the fabric play no part in this benchmark.

Kratos set-up: ``ShellThinElementCorotational3D3N`` (DKT bending + OPT membrane, corotational,
6 dofs per node) on the same right-diagonal triangulation as rftstatic
(:func:`rftstatic.mesh.trimesh.rectangle`); ``LinearElasticPlaneStress2DLaw``; the clamped edge
fixes all 6 dofs; ``ResidualBasedNewtonRaphsonStrategy`` with the incremental-update static
scheme, the block builder and ``DisplacementCriteria`` (||du|| / ||u|| < 1e-6, at most 50
iterations a step; on 51 x 11 nodes the tip drop agrees to 1e-7 with a 1e-8 residual criterion);
the gravity (nodal ``VOLUME_ACCELERATION``) applied in ``increments`` equal steps (5 is the fewest
that converge on 51 x 11 and 101 x 21 nodes); the mesh is moved every iteration (the element takes
its frame from the current coordinates: without moving, Newton stalls). Linear solver: Eigen's
SparseLU (LinearSolversApplication), else Kratos's skyline LU; the name is returned.

Units: SI inside (m, N, Pa, kg/m^3); the tip drop is returned in cm. Timed with
``time.perf_counter``: ``import_s`` (importing Kratos), ``build_s`` (model part, nodes, elements,
supports, strategy and its ``Initialize``) and ``solve_s`` (the load steps only: dof set-up,
assembly, factorisations, updates). The console output of Kratos is cut to warnings.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

from rftstatic.bench.problems import STRIP_LENGTH, STRIP_WIDTH

__all__ = ["REFERENCE_TIP_DROP_CM", "kratos_available", "solve_strip"]

REFERENCE_TIP_DROP_CM = 4.34468  # heavy elastica (inextensible), Sze & Zhou 2016 §4.1
GRAVITY = 9.80665  # [m/s^2]
REL_TOL, ABS_TOL, MAX_ITERATIONS = 1e-6, 1e-12, 50  # DisplacementCriteria; Newton iterations per step
ELEMENT = "ShellThinElementCorotational3D3N"
APPLICATIONS = ("StructuralMechanicsApplication", "LinearSolversApplication")
PIP_COMMAND = "pip install KratosMultiphysics KratosStructuralMechanicsApplication KratosLinearSolversApplication"


def kratos_available() -> bool:
    """Whether Kratos and its structural-mechanics application are installed (without importing them)."""
    try:
        spec = importlib.util.find_spec("KratosMultiphysics")
    except (ImportError, ValueError):
        return False
    return spec is not None and spec.origin is not None and (Path(spec.origin).parent / APPLICATIONS[0]).is_dir()


@contextlib.contextmanager
def _quiet_stdout():
    """File descriptor 1 to /dev/null: the Kratos kernel prints its banner from C++ when it is first imported."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def _import_kratos():
    """(KratosMultiphysics, StructuralMechanicsApplication, LinearSolversApplication or None), logger at WARNING."""
    if not kratos_available():
        raise ImportError(f"Kratos Multiphysics with its StructuralMechanicsApplication is missing: {PIP_COMMAND}")
    with _quiet_stdout():
        import KratosMultiphysics as KM

        KM.Logger.GetDefaultOutput().SetSeverity(KM.Logger.Severity.WARNING)
        import KratosMultiphysics.StructuralMechanicsApplication as SMA

        try:
            import KratosMultiphysics.LinearSolversApplication as LSA
        except ImportError:
            LSA = None
    return KM, SMA, LSA


def _linear_solver(KM, LSA):
    """A direct solver and its name: Eigen SparseLU if LinearSolversApplication is there, else skyline LU."""
    if LSA is not None and hasattr(LSA, "SparseLUSolver"):
        return LSA.SparseLUSolver(), "LinearSolversApplication.sparse_lu (Eigen SparseLU)"
    return KM.SkylineLUFactorizationSolver(), "skyline_lu_factorization (Kratos core)"


def strip_shell(B: float, C: float, weight: float) -> dict:
    """The isotropic shell of the module docstring for bending rigidity ``B`` [N m], membrane rigidity
    ``C`` [N/m] and weight ``weight`` [N/m^2]: thickness [m], E [Pa], nu [-], density [kg/m^3]."""
    t = math.sqrt(12.0 * B / C)
    return {"thickness": t, "E": C / t, "nu": 0.0, "density": weight / (t * GRAVITY)}


def solve_strip(nx: int, ny: int, increments: int = 5, threads: int | None = None) -> dict:
    """Solve the clamped strip with ``nx`` x ``ny`` nodes (along x, across) in ``increments`` load steps,
    on ``threads`` OpenMP threads (None: Kratos's default, ``OMP_NUM_THREADS`` or every core).

    Returns a JSON-ready dict: ``tip_drop_cm`` (-u_z at x = L, y = 0, linear along the free edge when
    ``ny`` is even) [cm]; ``error`` (tip_drop / 4.34468 - 1, signed) [-]; ``iterations`` (Newton
    iterations, all steps) and ``step_iterations`` (per step; the loop stops at a step that does not
    converge in 50 iterations, ``converged`` is then False); ``increments``; ``import_s``, ``build_s``,
    ``solve_s`` [s] (see the module docstring); ``nodes``; ``dofs`` (free unknowns, 6 per node off the
    clamp); ``system_size`` (the builder's equations, fixed rows included); ``elements``;
    ``linear_solver``; ``threads`` (Kratos's OpenMP threads); ``shell`` (the mapped thickness, E, nu,
    density, SI); ``kratos_version``.
    """
    from rftstatic.material import preset
    from rftstatic.mesh.trimesh import rectangle

    nx, ny, increments = int(nx), int(ny), int(increments)
    if increments < 1:
        raise ValueError(f"increments must be >= 1, got {increments}")
    t0 = time.perf_counter()
    KM, SMA, LSA = _import_kratos()
    if threads is not None:
        KM.ParallelUtilities.SetNumThreads(int(threads))
    t1 = time.perf_counter()

    L = STRIP_LENGTH
    mesh = rectangle(L, STRIP_WIDTH, nx, ny, origin=(0.0, -STRIP_WIDTH / 2))
    mat = preset("wool-kang-yu")
    shell = strip_shell(mat.Db[0, 0], mat.Dm[0, 0], mat.weight)

    model = KM.Model()
    mp = model.CreateModelPart("strip")
    mp.SetBufferSize(2)
    mp.ProcessInfo[KM.DOMAIN_SIZE] = 3
    for var in (KM.DISPLACEMENT, KM.ROTATION, KM.REACTION, KM.REACTION_MOMENT, KM.VOLUME_ACCELERATION):
        mp.AddNodalSolutionStepVariable(var)
    for i, (x, y) in enumerate(mesh.X.tolist(), start=1):  # Kratos ids are 1-based
        mp.CreateNewNode(i, x, y, 0.0)
    props = mp.GetProperties()[1]
    props[KM.YOUNG_MODULUS], props[KM.POISSON_RATIO] = shell["E"], shell["nu"]
    props[KM.THICKNESS], props[KM.DENSITY] = shell["thickness"], shell["density"]
    props[KM.CONSTITUTIVE_LAW] = SMA.LinearElasticPlaneStress2DLaw()
    for e, tri in enumerate((mesh.tri + 1).tolist(), start=1):
        mp.CreateNewElement(ELEMENT, e, tri, props)
    utils = KM.VariableUtils()
    pairs = [(f"{kind}_{c}", f"{reaction}_{c}") for kind, reaction in (("DISPLACEMENT", "REACTION"),
                                                                       ("ROTATION", "REACTION_MOMENT")) for c in "XYZ"]
    for dof, reaction in pairs:
        utils.AddDof(KM.KratosGlobals.GetVariable(dof), KM.KratosGlobals.GetVariable(reaction), mp)
    clamped = mesh.nodes_in_box(0.0, 0.0, -1.0, 1.0)
    clamp = mp.CreateSubModelPart("clamp")
    clamp.AddNodes((clamped + 1).tolist())
    for dof, _ in pairs:
        utils.ApplyFixity(KM.KratosGlobals.GetVariable(dof), True, clamp.Nodes)

    solver, solver_name = _linear_solver(KM, LSA)
    builder = KM.ResidualBasedBlockBuilderAndSolver(solver)
    criterion = KM.DisplacementCriteria(REL_TOL, ABS_TOL)
    scheme = KM.ResidualBasedIncrementalUpdateStaticScheme()
    strategy = KM.ResidualBasedNewtonRaphsonStrategy(mp, scheme, criterion, builder, MAX_ITERATIONS,
                                                     False, False, True)  # reactions, reform dofs, move mesh
    strategy.SetEchoLevel(0)
    strategy.Initialize()
    t2 = time.perf_counter()

    steps, converged = [], True
    for k in range(1, increments + 1):  # stops at the first step that fails (Newton diverges: nothing to gain)
        mp.CloneTimeStep(float(k))
        mp.ProcessInfo[KM.STEP] = k
        utils.SetVariable(KM.VOLUME_ACCELERATION, KM.Array3([0.0, 0.0, -GRAVITY * k / increments]), mp.Nodes)
        strategy.InitializeSolutionStep()
        strategy.Predict()
        ok = strategy.SolveSolutionStep()
        strategy.FinalizeSolutionStep()
        steps.append(int(mp.ProcessInfo[KM.NL_ITERATION_NUMBER]))
        if not ok:
            converged = False
            break
    t3 = time.perf_counter()

    edge = mesh.nodes_in_box(L, L, -1.0, 1.0)
    edge = edge[np.argsort(mesh.X[edge, 1])]
    uz = np.array([mp.GetNode(int(i) + 1).GetSolutionStepValue(KM.DISPLACEMENT_Z) for i in edge])
    tip_cm = -100.0 * float(np.interp(0.0, mesh.X[edge, 1], uz))
    return {"tip_drop_cm": tip_cm, "error": tip_cm / REFERENCE_TIP_DROP_CM - 1.0, "iterations": sum(steps),
            "step_iterations": steps, "converged": converged, "increments": increments,
            "import_s": t1 - t0, "build_s": t2 - t1, "solve_s": t3 - t2, "nodes": mesh.n_nodes,
            "dofs": 6 * (mesh.n_nodes - clamped.size), "system_size": int(builder.GetEquationSystemSize()),
            "elements": mesh.n_elements, "linear_solver": solver_name,
            "threads": int(KM.ParallelUtilities.GetNumThreads()), "shell": shell,
            "kratos_version": KM.KratosGlobals.Kernel.Version()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("nx", type=int, help="nodes along the length (x)")
    ap.add_argument("ny", type=int, help="nodes across the width (y)")
    ap.add_argument("increments", type=int, nargs="?", default=5, help="equal load steps (default 5)")
    ap.add_argument("--threads", type=int, default=None, help="OpenMP threads of Kratos (default: its own)")
    args = ap.parse_args(argv)
    print(json.dumps(solve_strip(args.nx, args.ny, args.increments, threads=args.threads)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
