"""Global adaptive remeshing (Sze & Zhou 2016, §5.2, steps a-i), for the static solver and for
dynamic relaxation.

One remesh (:func:`adapt_mesh` + :func:`transfer_state`):

e. h_target per triangle of the present mesh from its curvature, Eq. 29
   (:func:`rftstatic.sizefield.target_sizes`);
f. h_target to the square background grid with a gradation limit
   (:func:`rftstatic.sizefield.size_field`); the kinematic variables are carried by the old mesh
   itself (route ``"mesh"``, :mod:`rftstatic.transfer`) or by a background grid (``"grid"``);
g. a new advancing-front mesh of the flat reference sheet (:func:`rftstatic.mesher.generate`);
   the sheet's outline is recovered from the old mesh (:func:`reference_domain`): straight sides
   as polygons, circles exactly, so repeated remeshing does not shrink a disc;
h. U (and V) at the new nodes, then zero on the new mesh's supports;
and the model is rebuilt on the new mesh by the caller's factory (for a scene,
:func:`rftstatic.build.build_model` with ``mesh=``: supports, loads, probes and obstacles are
defined in reference coordinates, the bending stiffness and the lumped mass follow the mesh).

Drivers:

:func:`remesh_static` (a step beyond the paper, which remeshes only during dynamic relaxation)
    solve -> size a new mesh from the converged curvature -> transfer U -> solve again at full
    load from the transferred state, until the node count changes by less than ``tol`` (and, if
    given, the largest relative curvature |kappa| h is at most ``kappa_h_max``).
:func:`remesh_relax` (§6)
    advance the damped, mass-scaled (s = 100) explicit motion in chunks; remesh every ``every``
    steps, or as soon as max |kappa| h^2 exceeds ``kappa_h2_max`` (step d), transferring U and V;
    stop when the sheet is at rest on a mesh that would not change. The default stepper
    (:func:`explicit_advance`) damps with a fixed alpha or with :func:`critical_damping` (critical
    for the hanging sheet's slowest swing, which relaxes the drapes 2-4 times sooner than the
    paper's alpha = 5/s with s = 100), and finds the obstacle contacts through
    :class:`NearObstacle` candidate lists.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from dataclasses import dataclass, field

import numpy as np

from rftstatic.errors import ParameterError
from rftstatic.remesh.sizefield import curvature_magnitude, size_field
from rftstatic.remesh.transfer import METHODS, transfer_fields
from rftstatic.solvers.relaxation import RELAX_MASS_SCALE

DAMPING = ("fixed", "critical")
"""Damping of the remeshed relaxation: the scene's alpha, or critical for the sheet's slowest swing."""

log = logging.getLogger(__name__)

__all__ = ["reference_domain", "adapt_mesh", "transfer_state", "RemeshRecord", "RemeshStaticResult",
           "remesh_static", "refinable_maxima", "NearObstacle", "critical_damping", "explicit_advance",
           "RemeshRelaxResult", "remesh_relax"]


# --------------------------------------------------------------------------------------------- one remesh
def reference_domain(mesh, *, circle_tol=1e-6):
    """The outline of the flat sheet meshed by ``mesh``, as a mesher :class:`~rftstatic.mesher.Domain`.

    The boundary edges give closed loops (:meth:`Domain.from_segments`, which drops vertices on
    straight runs, so a rectangle comes back as its four corners). A loop of at least 8 vertices
    whose distances to their least-squares circle agree within ``circle_tol`` times the radius is
    replaced by that circle, so that the new boundary nodes lie on the true circle (route "mesh" of
    the transfer then extrapolates to the few new nodes just outside the old inscribed polygon).

    Parameters
    ----------
    mesh : :class:`rftstatic.mesh.TriMesh` (reference coordinates [m])
    circle_tol : relative radius spread below which a loop is taken as a circle [-]
    """
    from rftstatic.mesh.mesher import Domain, Loop

    dom = Domain.from_segments(mesh.X, mesh.boundary_edges)
    loops, changed = [], False
    for lp in dom.loops:
        v = lp.vertices
        if v is not None and len(v) >= 8:
            # Kasa fit: x^2 + y^2 = 2 a x + 2 b y + c
            A = np.column_stack([2 * v, np.ones(len(v))])
            sol = np.linalg.lstsq(A, (v**2).sum(axis=1), rcond=None)[0]
            centre = sol[:2]
            r = np.linalg.norm(v - centre, axis=1)
            R = float(np.sqrt(sol[2] + centre @ centre))
            if np.ptp(r) <= circle_tol * R:
                loops.append(Loop(center=centre, radius=float(r.mean()), orientation=lp.orientation))
                changed = True
                continue
        loops.append(lp)
    return Domain(loops) if changed else dom


def adapt_mesh(mesh, kappa, *, const, h_lower, h_upper, gradation=1.3, domain=None, spacing=None,
               smooth_iterations=4):
    """Steps e-g: a new mesh of ``mesh``'s sheet sized by Eq. 29 from the element curvature ``kappa``.

    Parameters
    ----------
    mesh : present :class:`rftstatic.mesh.TriMesh` [m]
    kappa : (E, 3) its element curvature (k_xx, k_yy, 2 k_xy) [1/m] (``model.curvature(U)``)
    const, h_lower, h_upper : Eq. 29 [m] (:mod:`rftstatic.sizefield`)
    gradation : gradation limit of the size field (ratio >= 1)
    domain : mesher Domain of the sheet (default :func:`reference_domain` of ``mesh``)
    spacing : background-grid spacing [m] (default in :func:`rftstatic.sizefield.size_field`)
    smooth_iterations : passed to :func:`rftstatic.mesher.generate`

    Returns
    -------
    new_mesh : :class:`rftstatic.mesh.TriMesh` in the same plane z0, ``info["quality"]`` the mesher's figures
    result : :class:`rftstatic.mesher.MeshResult`
    """
    from rftstatic.mesh.mesher import generate
    from rftstatic.mesh.trimesh import TriMesh

    if domain is None:
        domain = reference_domain(mesh)
    grid = size_field(mesh, kappa, const=const, h_lower=h_lower, h_upper=h_upper, gradation=gradation,
                      spacing=spacing, region=domain)
    res = generate(domain, grid, smooth_iterations=smooth_iterations)
    new = TriMesh(res.points, res.triangles, z0=mesh.z0, name=f"adapted {len(res.points)} nodes",
                  info={"generator": "advancing-front (remesh)", "quality": res.quality.as_dict()})
    return new, res


def transfer_state(old_model, new_model, U, V=None, *, method="mesh"):
    """Step h: U (N, 3) [m] and optionally V (N, 3) [m/s] of ``old_model`` at the nodes of ``new_model``.

    Supported dofs of the new model are set to zero (its supports prescribe zero displacement).
    Returns ``(U_new, V_new)`` (``V_new`` is None when ``V`` is).
    """
    fields = [U] if V is None else [U, V]
    out = transfer_fields(old_model.mesh, new_model.mesh.X, fields, method=method,
                          patches=old_model.patches if method == "patch" else None)
    free = new_model.free
    U_new = out[0] * free
    V_new = None if V is None else out[1] * free
    return U_new, V_new


@dataclass
class RemeshRecord:
    """One mesh of an adaptive run.

    Attributes
    ----------
    cycle : 0 for the initial mesh, then 1, 2, ... per remesh
    nodes, triangles : size of this mesh
    quality : the mesher's quality figures (``MeshQuality.as_dict()``; {} for a mesh not made by it)
    max_kappa_h : largest relative curvature |kappa| h on this mesh when it was left (or at the end) [-]
    max_kappa_h2 : largest |kappa| h^2 then [m]
    refinable_kappa_h, refinable_kappa_h2 : the same over the elements a new mesh can still make
        smaller (:func:`refinable_maxima`), which the settling tests use [-], [m]
    node_change : |N_next - N| / N of the mesh sized from this one's state [-] (nan if not sized)
    time, step : simulated time [s] and explicit steps when this mesh was made (remesh_relax)
    reason : why this mesh was made: "initial", "cycle", "every", "curvature", "rest"
    wall_time : meshing + solving (or advancing) on this mesh [s]
    solve : solver figures on this mesh (static: converged, iterations, load_steps, restarted)
    """

    cycle: int
    nodes: int
    triangles: int
    quality: dict
    max_kappa_h: float = float("nan")
    max_kappa_h2: float = float("nan")
    refinable_kappa_h: float = float("nan")
    refinable_kappa_h2: float = float("nan")
    node_change: float = float("nan")
    time: float = 0.0
    step: int = 0
    reason: str = "initial"
    wall_time: float = 0.0
    solve: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


def _factory(problem):
    """``mesh -> (model, extras)`` from a callable ``factory(mesh)`` (``mesh=None``: the initial mesh)."""
    if not callable(problem):
        raise TypeError(f"problem must be a callable mesh -> model (e.g. a scene's model factory, "
                        f"rftstatic.scenes.build.model_factory), got {type(problem).__name__}")

    def make(mesh=None):
        out = problem(mesh)
        return out if isinstance(out, tuple) else (out, {})

    return make


def _curvature_figures(model, U):
    kappa = model.curvature(U)
    mag = curvature_magnitude(kappa)
    h = model.mesh.element_size
    return kappa, float((mag * h).max()), float((mag * h * h).max())


BAND = 1.4
"""Upper end of the mesher's edge-length band (edges within [0.7, 1.4] of the target size)."""


def refinable_maxima(mesh, kappa, *, const, h_lower):
    """Largest |kappa| h and |kappa| h^2 [m] over the elements a new mesh could still make smaller.

    Eq. 29 clips the target size at ``h_lower`` (the explicit step would collapse otherwise), so an
    element whose curvature asks for less (sqrt(const / |kappa|) < h_lower) and which is already as
    small as the mesher makes it (mean side at most :data:`BAND` h_lower) keeps its |kappa| h for
    good: remeshing cannot lower it, and a test "max |kappa| h <= limit" over it never passes (the
    static route then ran its five cycles on every drape; measured |kappa| h = 1.2-1.5 at h_lower on
    the folds of the §6 scenes). Such elements are left out; every other element counts.

    Parameters
    ----------
    mesh : :class:`rftstatic.mesh.TriMesh` (``element_size`` [m])
    kappa : (E, 3) element curvature [1/m]
    const, h_lower : Eq. 29 [m]

    Returns
    -------
    (max |kappa| h [-], max |kappa| h^2 [m]); 0 when every element is at the size floor
    """
    mag = curvature_magnitude(kappa)
    h = mesh.element_size
    with np.errstate(divide="ignore"):
        wanted = np.sqrt(const / mag)  # inf where flat
    at_floor = (wanted < h_lower) & (h <= BAND * h_lower)
    keep = ~at_floor
    return float((mag * h)[keep].max(initial=0.0)), float((mag * h * h)[keep].max(initial=0.0))


def check_remesh_parameters(*, const, h_lower, h_upper, gradation=1.3, max_cycles=5, tol=0.05, kappa_h_max=None,
                            transfer="mesh", every=None, kappa_h2_max=None, damping="fixed") -> None:
    """Check the options of :func:`remesh_static` and :func:`remesh_relax` (any consistent units).

    Raises :class:`~rftstatic.errors.ParameterError` whose ``key`` names the parameter: const, h_lower,
    h_upper, gradation, tol must be positive finite numbers (kappa_h_max too unless None), h_lower <=
    h_upper, gradation >= 1, transfer in :data:`~rftstatic.remesh.transfer.METHODS`, damping in
    :data:`DAMPING`, every a positive and max_cycles a non-negative integer (every may be None),
    kappa_h2_max a positive length or None.
    """
    values = {"const": const, "h_lower": h_lower, "h_upper": h_upper, "gradation": gradation, "tol": tol,
              "kappa_h_max": kappa_h_max}
    for key, v in values.items():
        if key == "kappa_h_max" and v is None:
            continue
        if not (isinstance(v, (int, float, np.floating, np.integer)) and not isinstance(v, bool)
                and np.isfinite(v) and v > 0):
            raise ParameterError(key, f"must be a positive number, got {v!r}")
    if gradation < 1:
        raise ParameterError("gradation", f"must be >= 1 (a size ratio), got {gradation!r}")
    if h_lower > h_upper:
        raise ParameterError("h_lower", f"h_lower = {h_lower} exceeds h_upper = {h_upper}; Eq. 29 clips h_target "
                             "to [h_lower, h_upper]: swap them")
    if transfer not in METHODS:
        raise ParameterError("transfer", f'"{transfer}" is unknown; use one of {", ".join(METHODS)}')
    if damping not in DAMPING:
        raise ParameterError("damping", f'"{damping}" is unknown; use one of {", ".join(DAMPING)}')
    for key, v, low in (("every", every, 1), ("max_cycles", max_cycles, 0)):
        if v is None and key == "every":
            continue
        if not (isinstance(v, (int, np.integer)) and not isinstance(v, bool) and v >= low):
            raise ParameterError(key, f"must be a {'positive' if low else 'non-negative'} integer, got {v!r}")
    if kappa_h2_max is not None and not (isinstance(kappa_h2_max, (int, float)) and kappa_h2_max > 0):
        raise ParameterError("kappa_h2_max", f"must be a positive length or None (Eq. 28), got {kappa_h2_max!r}")


def _check_extent(mesh, h_lower, h_upper):
    """Element size bounds no larger than the sheet (the smaller side of its bounding box)."""
    lo, hi = mesh.X.min(axis=0), mesh.X.max(axis=0)
    extent = float((hi - lo).min())
    for name, v in (("h_lower", h_lower), ("h_upper", h_upper)):
        if v > extent:
            raise ParameterError(name, f"{name} = {v!r} m is larger than the sheet (smaller side {extent:.6g} m); "
                                 f"a flat region would get elements bigger than the domain: use {name} < {extent:.6g}")


# --------------------------------------------------------------------------------------------- static
@dataclass
class RemeshStaticResult:
    """Outcome of :func:`remesh_static`.

    Attributes
    ----------
    result : the :class:`rftstatic.static.StaticResult` on the final mesh (``result.U`` (N, 3) [m])
    model, extras : the final model and its extras (probes, obstacles)
    records : one :class:`RemeshRecord` per mesh solved
    converged : the mesh stopped changing (and, if given, |kappa| h <= kappa_h_max) within ``max_cycles``
    """

    result: object
    model: object
    extras: dict
    records: list
    converged: bool

    def table(self) -> list[dict]:
        return [r.as_dict() for r in self.records]


def _continuation(options):
    """Options that solve at full load straight from a transferred equilibrium (Newton from it: a
    ``start = "relax"`` of the first solve would throw the transferred state away and relax from flat)."""
    return options.from_state()


def remesh_static(problem, *, const, h_lower, h_upper, max_cycles=5, tol=0.05, kappa_h_max=None,
                  gradation=1.3, transfer="mesh", options=None, domain=None) -> RemeshStaticResult:
    """Static solution with global adaptive remeshing (module docstring).

    Parameters
    ----------
    problem : a callable ``factory(mesh) -> Model`` or ``-> (Model, extras)``; ``factory(None)`` gives
        the initial mesh's model (for a scene: :func:`rftstatic.scenes.build.model_factory`)
    const, h_lower, h_upper : Eq. 29 [m]: h_new = sqrt(const / |kappa|) clipped to [h_lower, h_upper]
    max_cycles : at most this many remeshes after the initial solve
    tol : stop when the next mesh's node count differs by less than this fraction [-] ...
    kappa_h_max : ... and the largest |kappa| h on the present mesh is at most this [-] (over the
        elements not already at the size floor h_lower, :func:`refinable_maxima`); None: the node
        count alone. An element at its Eq. 29 size has |kappa| h = sqrt(const |kappa|), up to
        const / h_lower where the size reaches the floor, so a cap below that is never met (the §6
        scenes: const / h_lower = 1, measured max |kappa| h 0.86-1.5 on settled meshes)
    gradation : gradation limit of the size field (ratio >= 1)
    transfer : ``"mesh"`` or ``"grid"`` (:mod:`rftstatic.transfer`)
    options : :class:`rftstatic.solvers.newton.StaticOptions` of the first solve (default: the
        defaults, without a progress bar); later solves start from the transferred state at
        full load (one load step) and fall back to the full load ramp from flat if that fails
    domain : mesher Domain of the sheet (default: :func:`reference_domain` of the initial mesh)

    Returns
    -------
    :class:`RemeshStaticResult`

    Raises
    ------
    ValueError
        bad Eq. 29 parameters (named), ``tol`` or ``max_cycles``
    rftstatic.static.ConvergenceError
        when a solve fails even from flat (its ``.result`` is the last equilibrium)
    """
    from rftstatic.errors import ConvergenceError
    from rftstatic.solvers.static import StaticOptions, solve_static

    check_remesh_parameters(const=const, h_lower=h_lower, h_upper=h_upper, gradation=gradation,
                            max_cycles=max_cycles, tol=tol, kappa_h_max=kappa_h_max, transfer=transfer)
    make = _factory(problem)
    if options is None:
        options = StaticOptions(progress=False)
    t0 = time.perf_counter()
    model, extras = make(None)
    _check_extent(model.mesh, h_lower, h_upper)
    if domain is None:
        domain = reference_domain(model.mesh)
    result = solve_static(model, options=options)
    records = [RemeshRecord(0, model.mesh.n_nodes, model.mesh.n_elements, dict(model.mesh.info.get("quality", {})),
                            solve=_static_figures(result, restarted=False))]
    converged = False
    for cycle in range(1, int(max_cycles) + 1):
        kappa, kh, kh2 = _curvature_figures(model, result.U)
        rec = records[-1]
        rec.max_kappa_h, rec.max_kappa_h2 = kh, kh2
        rec.refinable_kappa_h, rec.refinable_kappa_h2 = refinable_maxima(model.mesh, kappa, const=const, h_lower=h_lower)
        t_mesh = time.perf_counter()
        new_mesh, _ = adapt_mesh(model.mesh, kappa, const=const, h_lower=h_lower, h_upper=h_upper,
                                 gradation=gradation, domain=domain)
        rec.node_change = abs(new_mesh.n_nodes - model.mesh.n_nodes) / model.mesh.n_nodes
        rec.wall_time = t_mesh - t0
        log.info("remesh_static cycle %d: %d nodes, max |kappa| h %.3g, next mesh %d nodes (change %.1f %%)",
                 rec.cycle, rec.nodes, kh, new_mesh.n_nodes, 100 * rec.node_change)
        if rec.node_change < tol and (kappa_h_max is None or rec.refinable_kappa_h <= kappa_h_max):
            converged = True
            break
        t0 = t_mesh
        new_model, new_extras = make(new_mesh)
        U0, _ = transfer_state(model, new_model, result.U, method=transfer)
        restarted = False
        try:
            result = solve_static(new_model, U0=U0, options=_continuation(options))
        except ConvergenceError as exc:
            log.info("remesh_static cycle %d: no equilibrium from the transferred state (%s); solving from flat",
                     cycle, exc)
            restarted = True
            result = solve_static(new_model, options=options)
        model, extras = new_model, new_extras
        records.append(RemeshRecord(cycle, new_mesh.n_nodes, new_mesh.n_elements, new_mesh.info["quality"],
                                    reason="cycle", solve=_static_figures(result, restarted=restarted)))
    rec = records[-1]
    if not converged:
        kappa, rec.max_kappa_h, rec.max_kappa_h2 = _curvature_figures(model, result.U)
        rec.refinable_kappa_h, rec.refinable_kappa_h2 = refinable_maxima(model.mesh, kappa, const=const, h_lower=h_lower)
        rec.wall_time = time.perf_counter() - t0
        log.warning("remesh_static: the mesh still changes after %d cycles (max |kappa| h %.3g)",
                    max_cycles, rec.max_kappa_h)
    return RemeshStaticResult(result=result, model=model, extras=extras, records=records, converged=converged)


def _static_figures(result, *, restarted):
    return {"converged": bool(result.converged), "iterations": int(result.iterations),
            "load_steps": len(result.load_steps), "restarted": restarted, "solve_time": float(result.wall_time)}


# --------------------------------------------------------------------------------------------- relaxation
CHAIN = 1.2024
"""Fundamental frequency of a hanging chain of length l, in units of sqrt(g / l) (j_01 / 2 = 2.4048 / 2)."""


def critical_damping(model, U, *, mass_scale, alpha_max):
    """Mass damping [1/s] that is critical for the slowest swing of the hanging sheet, at most ``alpha_max``.

    The lowest mode of a sheet hanging ``l`` below its support is close to that of a hanging chain,
    ``omega_1 = 1.2 sqrt(g / l)``; with the mass scaled by s (the weight is not) the load gives the
    mass the acceleration g / s, so ``omega_1 = 1.2 sqrt(g / (s l))`` and critical damping is
    ``alpha = 2 omega_1``. ``l`` is the present largest sag ``-min U_z`` [m]. Dynamic relaxation
    converges fastest near critical damping of its slowest mode: a larger alpha lets the overdamped
    swing creep at the rate omega_1^2 / alpha, a smaller one lets it ring. (With the mass scaled by
    s, a damping alpha gives the motion of the real sheet damped by alpha sqrt(s), slowed down
    sqrt(s) times: the same number of steps.) Measured with s = 100 on
    the 50 x 50 cm sheet over the round pedestal: the paper's alpha = 5 / s (chosen for the real
    mass, §4.6) is critical for a 2.3 cm hang and came to rest after 50.6 s (the drape hangs 25.7 cm:
    alpha = 1.48 / s, at rest after 28 s).

    Returns ``alpha_max`` while the sheet has not sagged (``-min U_z <= 0``) or carries no load.

    Parameters
    ----------
    model : the model (``load`` [N], lumped mass from :func:`rftstatic.timestep.lumped_mass`)
    U : (N, 3) displacements [m]
    mass_scale : s [-]
    alpha_max : upper bound [1/s] (the scene's alpha)
    """
    from rftstatic.solvers.timestep import lumped_mass

    sag = float(-U[:, 2].min(initial=0.0))
    mass = float(lumped_mass(model, mass_scale)[model.free.any(axis=1)].sum())
    weight = float(-np.where(model.free, model.load, 0.0)[:, 2].sum())
    if not (sag > 0 and weight > 0 and mass > 0):
        return float(alpha_max)
    omega = CHAIN * np.sqrt(weight / mass / sag)
    return float(min(alpha_max, 2.0 * omega))


class NearObstacle:
    """An obstacle whose signed distance is computed only for the points near it (a candidate list).

    For the kinematic contact of the explicit steps (:func:`rftstatic.contact.kinematic_contact`
    needs phi only to find phi < 0, and the normal there). The exact distance of every point is
    computed when the list is (re)made; the candidates are the points within ``margin`` of the
    obstacle. Until some point has moved more than ``margin / 2`` since then, only the candidates
    are evaluated: a signed distance changes no faster than the point moves (it is 1-Lipschitz), so
    every other point is still more than ``margin / 2`` outside, and it gets that lower bound with a
    zero normal. The contact is therefore the same as with the plain obstacle, and a step pays for
    the few points near the obstacle. Measured on the 50 x 50 cm sheet over the round pedestal
    (~1900 nodes): the kinematic contact took more time than the internal force before.

    Parameters
    ----------
    obstacle : any obstacle (``signed_distance``, ``normal_gradient``)
    margin : candidate distance [m]; :meth:`reset` sets it (e.g. to the mean element size)
    """

    def __init__(self, obstacle, margin):
        self.obstacle = obstacle
        self.margin = float(margin)
        self.refreshes = 0
        self._list = None  # (candidate indices, positions at refresh, distances at refresh)

    def reset(self, margin=None):
        """Forget the candidate list (a new mesh); optionally a new ``margin`` [m]."""
        if margin is not None:
            self.margin = float(margin)
        self._list = None

    def signed_distance(self, x):
        x = np.asarray(x, dtype=float)
        c = self._list
        if c is not None and c[1].shape == x.shape:
            idx, x_ref, phi_ref = c
            d = x - x_ref
            moved = float(np.sqrt(np.max(np.einsum("ni,ni->n", d, d), initial=0.0)))
            if moved <= 0.5 * self.margin:
                phi = phi_ref - moved
                normal = np.zeros_like(x)
                if len(idx):
                    phi[idx], normal[idx] = self.obstacle.signed_distance(x[idx])
                return phi, normal
        phi, normal = self.obstacle.signed_distance(x)
        self._list = (np.flatnonzero(phi < self.margin), x.copy(), phi.copy())
        self.refreshes += 1
        return phi, normal

    def normal_gradient(self, x):
        return self.obstacle.normal_gradient(x)


def explicit_advance(*, alpha, mass_scale=RELAX_MASS_SCALE, dt=None, obstacles=(), safety=0.9, backend="auto",
                     energy_check=False, damping="fixed"):
    """An ``advance(model, U, V, n_steps) -> (U, V, t)`` stepper on :func:`rftstatic.explicit.run_explicit`.

    ``V`` is the half-step velocity v_(n-1/2) [m/s] and is passed back in with ``start="given"``, so
    chunks continue the central-difference sequence exactly. ``t`` is the time advanced [s]. The
    stable step is estimated once per model (``dt=None``; ``safety`` times the critical step at the
    state the mesh starts from, with the damping ``alpha``), with the mass scaled by ``mass_scale``
    (§6: 100; the weight is not scaled). ``energy_check=True`` makes every chunk re-estimate the
    step (a Lanczos run per chunk, and a warning whenever the sheet has stiffened by a few 0.1 %
    since the mesh's estimate); by default the driver only checks that the state stays finite.

    ``damping="fixed"``: every chunk is damped with ``alpha`` [1/s]. ``damping="critical"``: each
    chunk with :func:`critical_damping` of the state it starts from (at most ``alpha``).
    ``advance.alphas`` lists the damping of every chunk [1/s]. The obstacles act kinematically
    through :class:`NearObstacle` candidate lists (the same contact, fewer distance evaluations).
    """
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.timestep import stable_time_step

    if damping not in DAMPING:
        raise ValueError(f'damping = "{damping}" is unknown; use one of {", ".join(DAMPING)}')
    obstacles = (obstacles,) if hasattr(obstacles, "signed_distance") else tuple(obstacles)
    near = tuple(NearObstacle(ob, 0.0) for ob in obstacles)
    cache = {}

    def advance(model, U, V, n_steps):
        if cache.get("model") is not model:
            for ob in near:  # candidates within a mean element size of the obstacle
                ob.reset(float(model.mesh.element_size.mean()))
            cache.clear()
            cache["model"] = model
        step = dt
        if step is None:
            if "dt" not in cache:
                # alpha bounds the chunk's damping, and a larger damping shortens the critical step
                cache["dt"] = stable_time_step(model, U, mass_scale=mass_scale, alpha=alpha, safety=safety).dt
            step = cache["dt"]
        a = alpha if damping == "fixed" else critical_damping(model, U, mass_scale=mass_scale, alpha_max=alpha)
        advance.alphas.append(a)
        run = run_explicit(model, t_end=n_steps * step, dt=step, alpha=a, mass_scale=mass_scale,
                           obstacles=near, U0=U, V0=V, start="given", sample_every=max(1, n_steps),
                           progress=False, energy_check=energy_check, backend=backend)
        return run.U, run.V, run.t

    advance.mass_scale = mass_scale
    advance.alphas = []
    return advance


@dataclass
class RemeshRelaxResult:
    """Outcome of :func:`remesh_relax`: final U, V (N, 3) [m, m/s], model and extras, the time [s]
    and steps advanced, one :class:`RemeshRecord` per mesh, whether the sheet came to rest on a
    mesh that no longer changes, and how many triggered remeshes were skipped (mesh settled)."""

    U: np.ndarray
    V: np.ndarray
    model: object
    extras: dict
    t: float
    steps: int
    records: list
    converged: bool
    skipped: int = 0


def remesh_relax(problem, *, const, h_lower, h_upper, advance=None, alpha=None, mass_scale=RELAX_MASS_SCALE,
                 damping="fixed", every=None, kappa_h2_max=None, chunk=200, max_steps=100_000, max_remesh=50,
                 tol=0.05, tol_force=1e-4, tol_kinetic=1e-8, skip_settled=True, gradation=1.3, transfer="mesh",
                 domain=None, U0=None, V0=None, residual=None) -> RemeshRelaxResult:
    """Dynamic relaxation with global adaptive remeshing (§5.2 a-i, §6).

    The motion is advanced ``chunk`` steps at a time. After each chunk (step d) the mesh is
    remeshed when ``every`` steps have passed since the last remesh, or when the largest
    |kappa| h^2 exceeds ``kappa_h2_max`` [m]; U and V are transferred (step h). When the sheet is
    at rest (out-of-balance force on the free dofs < ``tol_force`` |P| and kinetic energy <
    ``tol_kinetic`` times its peak on the present mesh, or zero), the mesh it would get is sized:
    a node-count change below ``tol`` ends the run (converged), otherwise it remeshes and goes on.

    Parameters
    ----------
    problem : ``factory(mesh) -> Model | (Model, extras)`` (as in :func:`remesh_static`)
    const, h_lower, h_upper : Eq. 29 [m]
    advance : ``advance(model, U, V, n_steps) -> (U, V, t_advanced)``; default
        :func:`explicit_advance` with ``alpha``, ``mass_scale`` and the scene's obstacles
    alpha : mass damping [1/s] of the default stepper (required without ``advance``; with
        ``damping="critical"`` its upper bound)
    mass_scale : mass scaling s of the default stepper and of the kinetic energy [-] (§6: 100)
    damping : ``"fixed"`` or ``"critical"`` (:func:`critical_damping`), default stepper
    every : remesh every this many steps (None: only on curvature or at rest)
    kappa_h2_max : remesh when max |kappa| h^2 exceeds this [m] (None: never on curvature), over
        the elements not already at the size floor h_lower (:func:`refinable_maxima`)
    chunk : steps per call of ``advance``
    max_steps, max_remesh : limits (the run returns ``converged=False`` at max_steps)
    tol : relative node-count change below which the mesh counts as settled [-] (and, with
        ``kappa_h2_max``, max |kappa| h^2 <= kappa_h2_max)
    skip_settled : a remesh triggered by ``every`` or by the curvature is skipped when the mesh is
        settled. Measured on the clamped strip (s = 100, alpha = 3/s): remeshing every 5000 steps
        regardless kept the strip swinging for 200 000 steps (each new mesh differs by a few nodes
        and the transfer restarts the oscillation, as §5 warns); skipping settled meshes, it came
        to rest.
    U0, V0 : (N, 3) start on the initial mesh (default zero)
    residual : ``residual(model, U) -> (N, 3)`` [N], the out-of-balance force of the rest test (default
        ``model.residual(U)``; with kinematic obstacles,
        :func:`rftstatic.contact.kinematic.contact_reaction_residual` takes their reaction off)

    Returns
    -------
    :class:`RemeshRelaxResult`
    """
    from rftstatic.solvers.timestep import lumped_mass

    make = _factory(problem)
    if int(chunk) < 1:
        raise ValueError(f"chunk = {chunk!r} must be a positive number of steps")
    check_remesh_parameters(const=const, h_lower=h_lower, h_upper=h_upper, gradation=gradation, tol=tol,
                            transfer=transfer, every=every, kappa_h2_max=kappa_h2_max, damping=damping)
    if residual is None:
        def residual(model, U):
            return model.residual(U)
    model, extras = make(None)
    _check_extent(model.mesh, h_lower, h_upper)
    if advance is None:
        if alpha is None:
            raise ValueError("alpha (mass damping [1/s]) is needed by the default explicit stepper; or pass advance=")
        advance = explicit_advance(alpha=alpha, mass_scale=mass_scale, obstacles=extras.get("obstacles", ()),
                                   damping=damping)
    if domain is None:
        domain = reference_domain(model.mesh)
    N = model.mesh.n_nodes
    U = np.zeros((N, 3)) if U0 is None else np.array(U0, dtype=float)
    V = np.zeros((N, 3)) if V0 is None else np.array(V0, dtype=float)
    t, steps, since, n_remesh, skipped = 0.0, 0, 0, 0, 0
    peak = 0.0
    wall = time.perf_counter()
    records = [RemeshRecord(0, N, model.mesh.n_elements, dict(model.mesh.info.get("quality", {})))]
    converged = False
    while steps < max_steps:
        n = int(min(chunk, max_steps - steps))
        U, V, dt_adv = advance(model, U, V, n)
        if not (np.isfinite(U).all() and np.isfinite(V).all()):
            raise FloatingPointError(f"remesh_relax: non-finite state after step {steps + n} (t = {t:.4g} s) on a "
                                     f"mesh of {model.mesh.n_nodes} nodes; reduce the time step (safety) or raise alpha")
        t += float(dt_adv)
        steps += n
        since += n
        kappa, kh, kh2 = _curvature_figures(model, U)
        rkh, rkh2 = refinable_maxima(model.mesh, kappa, const=const, h_lower=h_lower)
        mass = lumped_mass(model, mass_scale)
        kinetic = 0.5 * float(np.einsum("n,ni,ni->", mass, V, V))
        peak = max(peak, kinetic)
        P = np.where(model.free, model.load, 0.0)
        r = float(np.linalg.norm(np.where(model.free, residual(model, U), 0.0)))
        rest = r <= tol_force * max(float(np.linalg.norm(P)), 1e-300) and (kinetic <= tol_kinetic * peak or kinetic == 0)
        reason = ("rest" if rest else "every" if every is not None and since >= every
                  else "curvature" if kappa_h2_max is not None and rkh2 > kappa_h2_max else None)
        if reason is None:
            continue
        if n_remesh >= max_remesh:
            if rest:
                converged = False
                break
            continue
        new_mesh, _ = adapt_mesh(model.mesh, kappa, const=const, h_lower=h_lower, h_upper=h_upper,
                                 gradation=gradation, domain=domain)
        rec = records[-1]
        rec.max_kappa_h, rec.max_kappa_h2 = kh, kh2
        rec.refinable_kappa_h, rec.refinable_kappa_h2 = rkh, rkh2
        rec.node_change = abs(new_mesh.n_nodes - model.mesh.n_nodes) / model.mesh.n_nodes
        settled = rec.node_change < tol and (kappa_h2_max is None or rkh2 <= kappa_h2_max)
        if rest and settled:
            converged = True
            break
        if settled and skip_settled:
            since = 0
            skipped += 1
            continue
        new_model, new_extras = make(new_mesh)
        U, V = transfer_state(model, new_model, U, V, method=transfer)
        model, extras = new_model, new_extras
        n_remesh += 1
        since, peak = 0, 0.0
        now = time.perf_counter()
        rec.wall_time, wall = now - wall, now
        records.append(RemeshRecord(n_remesh, new_mesh.n_nodes, new_mesh.n_elements, new_mesh.info["quality"],
                                    time=t, step=steps, reason=reason))
        log.info("remesh_relax: t = %.4g s, step %d (%s): %d -> %d nodes, max |kappa| h %.3g",
                 t, steps, reason, rec.nodes, new_mesh.n_nodes, kh)
    rec = records[-1]
    if not np.isfinite(rec.max_kappa_h):
        kappa, rec.max_kappa_h, rec.max_kappa_h2 = _curvature_figures(model, U)
        rec.refinable_kappa_h, rec.refinable_kappa_h2 = refinable_maxima(model.mesh, kappa, const=const, h_lower=h_lower)
    rec.wall_time = time.perf_counter() - wall
    if not converged:
        log.warning("remesh_relax: not at rest on a settled mesh after %d steps (t = %.4g s, %d remeshes)",
                    steps, t, n_remesh)
    return RemeshRelaxResult(U=U, V=V, model=model, extras=extras, t=t, steps=steps, records=records,
                             converged=converged, skipped=skipped)
