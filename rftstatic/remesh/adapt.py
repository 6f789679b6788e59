"""Global adaptive remeshing (Sze & Zhou 2016, §5.2, steps a-i), for the static solver and for
dynamic relaxation.

One remesh (:func:`adapt_mesh` + :func:`transfer_state`):

e. h_target per triangle of the present mesh from its curvature, Eq. 29
   (:func:`rftstatic.remesh.sizefield.target_sizes`);
f. h_target to the square background grid with a gradation limit
   (:func:`rftstatic.remesh.sizefield.size_field`); the kinematic variables are carried by the old mesh
   itself (route ``"mesh"``, :mod:`rftstatic.remesh.transfer`) or by a background grid (``"grid"``);
g. a new advancing-front mesh of the flat reference sheet (:func:`rftstatic.mesh.mesher.generate`);
   the sheet's outline is recovered from the old mesh (:func:`reference_domain`): straight sides
   as polygons, circles exactly, so repeated remeshing does not shrink a disc;
h. U (and V) at the new nodes, then zero on the new mesh's supports; the frictions' committed slips (bending and
   shear hysteresis, per element) on the new elements by the old element holding each new centroid
   (:func:`carry_slip`);
and the model is rebuilt on the new mesh by the caller's factory (for a scene,
:func:`rftstatic.scenes.build.build_model` with ``mesh=``: supports, loads, probes and obstacles are
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
from dataclasses import dataclass, field

import numpy as np

from rftstatic.element.curvature import curvature_norm
from rftstatic.mesh import GRADATION
from rftstatic.remesh.sizefield import check_size_bounds, size_field
from rftstatic.remesh.transfer import element_values, transfer_fields

DAMPING = ("fixed", "critical")
"""Damping of the remeshed relaxation: the scene's alpha, or critical for the sheet's slowest swing."""

log = logging.getLogger(__name__)

__all__ = ["reference_domain", "adapt_mesh", "transfer_state", "carry_slip", "RemeshRecord", "refinable_maxima",
           "DAMPING"]


# --------------------------------------------------------------------------------------------- one remesh
def reference_domain(mesh, *, circle_tol=1e-6):
    """The outline of the flat sheet meshed by ``mesh``, as a mesher :class:`~rftstatic.mesh.mesher.Domain`.

    The boundary edges give closed loops (:meth:`Domain.from_segments`, which drops vertices on
    straight runs, so a rectangle comes back as its four corners). A loop of at least 8 vertices
    whose distances to their least-squares circle agree within ``circle_tol`` times the radius is
    replaced by that circle, so that the new boundary nodes lie on the true circle (route "mesh" of
    the transfer then extrapolates to the few new nodes just outside the old inscribed polygon).

    Parameters
    ----------
    mesh : :class:`rftstatic.mesh.trimesh.TriMesh` (reference coordinates [m])
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


def adapt_mesh(mesh, kappa, *, const, h_lower, h_upper, gradation=GRADATION, domain=None, spacing=None,
               smooth_iterations=4):
    """Steps e-g: a new mesh of ``mesh``'s sheet sized by Eq. 29 from the element curvature ``kappa``.

    Parameters
    ----------
    mesh : present :class:`rftstatic.mesh.trimesh.TriMesh` [m]
    kappa : (E, 3) its element curvature (k_xx, k_yy, 2 k_xy) [1/m] (``model.curvature(U)``)
    const, h_lower, h_upper : Eq. 29 [m] (:mod:`rftstatic.remesh.sizefield`)
    gradation : gradation limit of the size field (ratio >= 1)
    domain : mesher Domain of the sheet (default :func:`reference_domain` of ``mesh``)
    spacing : background-grid spacing [m] (default in :func:`rftstatic.remesh.sizefield.size_field`)
    smooth_iterations : passed to :func:`rftstatic.mesh.mesher.generate`

    Returns
    -------
    new_mesh : :class:`rftstatic.mesh.trimesh.TriMesh` in the same plane z0, ``info["quality"]`` the mesher's figures
    result : :class:`rftstatic.mesh.mesher.MeshResult`
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


def carry_slip(old_model, slip, new_model):
    """The frictions' committed slips ``(E_old, k)`` of ``old_model``'s state on the elements of ``new_model``:
    ``(E_new, k)`` (:func:`rftstatic.remesh.transfer.element_values`: each new element takes the slip of the old
    element holding its centroid), or None when ``slip`` is (no friction). Mesh sequencing
    (:mod:`rftstatic.app.levels`) and both adaptive remeshing drivers carry the slips with it, so the next mesh
    starts from the history of the drape it takes over, not from a virgin fabric: the bending slip is a curvature
    [1/m] in material axes and the shear slip an angle [-] (:meth:`rftstatic.model.model.Model.initial_slip`), per
    element, neither depending on the element size. The two models have the same fabric, so the same columns."""
    if slip is None:
        return None
    return element_values(old_model.mesh, slip, new_model.mesh)


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
    mag = curvature_norm(kappa)
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
    mesh : :class:`rftstatic.mesh.trimesh.TriMesh` (``element_size`` [m])
    kappa : (E, 3) element curvature [1/m]
    const, h_lower : Eq. 29 [m]

    Returns
    -------
    (max |kappa| h [-], max |kappa| h^2 [m]); 0 when every element is at the size floor
    """
    mag = curvature_norm(kappa)
    h = mesh.element_size
    with np.errstate(divide="ignore"):
        wanted = np.sqrt(const / mag)  # inf where flat
    at_floor = (wanted < h_lower) & (h <= BAND * h_lower)
    keep = ~at_floor
    return float((mag * h)[keep].max(initial=0.0)), float((mag * h * h)[keep].max(initial=0.0))


def _check_extent(mesh, const, h_lower, h_upper):
    """The Eq. 29 parameters, with size bounds no larger than the sheet (the smaller side of its box)."""
    lo, hi = mesh.X.min(axis=0), mesh.X.max(axis=0)
    check_size_bounds(const=const, h_lower=h_lower, h_upper=h_upper, extent=float((hi - lo).min()))



