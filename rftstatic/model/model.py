"""The RF model: everything that is built once per mesh, and the total potential energy.

``Model`` owns the mesh, its patches and image-node rules, the material, the constant bending
stiffness K_b (Eq. 13), the membrane operator of RFT3 or RFT6, supports, the external load and the
contact term. Its methods evaluate, for a displacement field ``U (N, 3)`` [m] and a load factor
``lam``, the total potential energy (docs/theory/path-following.md)

    Pi(U) = E_b + E_m + E_c + E_s - lam P . U,

E_b holds the hinges of the mesh's creases (``mesh.folds``, attribute ``hinges``:
:class:`rftstatic.element.hinge.FoldHinges`), ``E_s`` is the self-contact energy
(:class:`rftstatic.contact.self_contact.law.SelfContact`, optional); with bending
hysteresis (``material.hysteresis``, attribute ``friction``: :class:`rftstatic.element.hysteresis.BendingFriction`)
E_b also holds the friction's incremental potential at the committed slip (``State.slip``, keyword ``slip``);
with nonlinear bending (``material.nonlinear_bending``, attribute ``bending_softening``:
:class:`rftstatic.element.nonlinear_bending.BendingSoftening`) E_b also holds its softening correction;
with shear hysteresis (``material.shear_hysteresis``, attribute ``shear_friction``:
:class:`rftstatic.element.shear_friction.ShearFriction`) E_m also holds the shear friction's incremental potential
at its committed slip. Both frictions' slips travel as one array (keyword ``slip``, ``State.slip``,
:meth:`Model.initial_slip`): columns 0-1 the bending friction's (warp, weft) when there is one, the last the
shear friction's when there is one,

its gradient (the out-of-balance force) and its Hessian (the tangent) on the assembly plan.
A Model is read-only once built (:class:`~rftstatic.model.frozen.Frozen`): what a solve advances or
caches (``U``, the contact caches, the self-contact stiffness scale, the potential loads' branches, the slip)
lives in its :class:`~rftstatic.model.state.State` and reaches these methods as keywords.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rftstatic.compiled import choose_kernels
from rftstatic.element.axis_terms import axis_terms
from rftstatic.element.curvature import curvature_norm
from rftstatic.element.hinge import fold_hinges
from rftstatic.element.hysteresis import bending_friction
from rftstatic.element.membrane import ELEMENTS, membrane_operator
from rftstatic.element.nonlinear_bending import nonlinear_bending
from rftstatic.element.patch import bending_stiffness, build_patches, curvature
from rftstatic.element.shear_friction import shear_friction
from rftstatic.material import Material
from rftstatic.mesh.trimesh import TriMesh
from rftstatic.model.assembly import AssemblyPlan, scatter_forces, scatter_matrices
from rftstatic.model.frozen import Frozen

log = logging.getLogger(__name__)

LOCKING_WARN = 1e4
"""Locking number ``(C/B) h^2`` [-] above which an RFT6 model warns of membrane locking (see
:func:`locking_number`). Measured on the wool strip of §4.1 (tip error against the heavy elastica,
RFT6, C/B scaled; validation/stability.md): 0.02 % at 5e3, 0.5 % at 2e4, 2.1 % at 5e4, 3.3 % at 8e4,
8 % at 8e5; the warning starts below the level (2e4) where the strip leaves its 0.5 % tolerance."""


def locking_number(mesh: TriMesh, material: Material) -> float:
    """``max_i (D^m_ii / D^b_ii) h^2`` [-], membrane over bending rigidity times the mean element size squared.

    RFT6 averages the strains of the six-node quadratic interpolation (§3); under pure bending
    (nodes on a cylinder) those strains are about twice the CST's, (kappa h)^2 / 12 against
    (kappa h)^2 / 24, and unlike the CST's they cannot all be relieved by moving the nodes: the
    parasitic membrane energy, relative to the bending energy, grows with this number. Wool on the
    paper's meshes: 3e3-8e3 (pedestals, 61 x 61 sphere), 1.7e4 (80 cm sheet at 81 x 81), 6e4 (17 x 17
    sphere, 100 cm hanging sheet), 1.2e5 (the 371-node unstructured mesh of Fig. 1 and 9).
    """
    Dm, Db = np.asarray(material.Dm, float), np.asarray(material.Db, float)
    ratio = max((Dm[i, i] / Db[i, i] for i in (0, 1) if Db[i, i] > 0), default=0.0)
    h = float(mesh.element_size.mean())
    return float(ratio * h * h)


@dataclass
class Supports:
    """Prescribed displacements: zero, or (explicit runs) moving at a prescribed velocity.

    Attributes
    ----------
    clamped : node indices held fixed with zero slope across clamped edges (image rule U_img = U_c)
    pinned : node indices held fixed, free to rotate
    fixed : (N, 3) bool, further single components held fixed (e.g. in-plane rigid modes)
    velocity : (N, 3) velocity [m/s] of the held components in explicit runs (a dragged edge,
        :mod:`rftstatic.solvers.explicit`), zero elsewhere; None: all at rest
    """

    clamped: np.ndarray
    pinned: np.ndarray
    fixed: np.ndarray
    velocity: np.ndarray | None = None

    @classmethod
    def none(cls, n_nodes):
        empty = np.zeros(0, dtype=np.int64)
        return cls(empty, empty.copy(), np.zeros((n_nodes, 3), dtype=bool))

    def fixed_mask(self) -> np.ndarray:
        m = self.fixed.copy()
        m[self.clamped] = True
        m[self.pinned] = True
        return m


def gravity_load(mesh: TriMesh, weight: float, direction=(0.0, 0.0, -1.0)) -> np.ndarray:
    """Nodal weight ``(N, 3)`` [N] of a sheet of areal weight ``weight`` [N/m^2] (a third per vertex)."""
    return np.outer(mesh.node_area * weight, np.asarray(direction, float))


def edge_load(mesh: TriMesh, edges: np.ndarray, force_per_length) -> np.ndarray:
    """Nodal forces ``(N, 3)`` [N] of a uniform line load [N/m] on ``edges (B, 2)`` (half per end)."""
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    length = np.linalg.norm(mesh.X[edges[:, 1]] - mesh.X[edges[:, 0]], axis=1)
    w = np.repeat(0.5 * length, 2)
    P = np.zeros((mesh.n_nodes, 3))
    share = np.bincount(edges.ravel(), w, minlength=mesh.n_nodes)
    return P + np.outer(share, np.asarray(force_per_length, float))


class Model(Frozen):
    """An RF triangle model of a flat fabric sheet (see module docstring), read-only once built.

    Parameters
    ----------
    mesh : reference mesh [m]
    material : rigidities and weight (SI)
    element : ``"RFT3"`` or ``"RFT6"``
    supports : prescribed displacements (default: none)
    load : (N, 3) external nodal load at load factor 1 [N] (default: zero)
    contact : an object with ``energy(x)``, ``force(x)``, ``tangent_blocks(x)`` (penalty contact)
    self_contact : the sheet's self-contact (an object with ``evaluate(x, tangent=, cache=)`` returning
        energy, force ``(N, 3)`` and pair blocks ``(A, 12, 12)`` over ``nodes (A, 4)``, ``new_pairs()`` and
        ``max_step_fraction(x, dx, cache=)``: :class:`rftstatic.contact.self_contact.law.SelfContact`), or None
    membrane : include the membrane energy (``False`` gives the linear Kirchhoff plate)
    load_terms : loads with a potential scaled by the load factor, e.g.
        :class:`rftstatic.model.loads.LeverMoment` (methods ``potential(x, branch)``, ``force``,
        ``tangent_blocks``, ``branch(x, previous)``; the branches live in the State; optionally ``couplings()``,
        the node pairs (P, 2) its blocks couple beyond the patches, :class:`rftstatic.model.loads.SeamSprings`)
    quiet : log the model's warnings (``warnings``: membrane locking) at debug level, not warning
        level (a remeshed run builds one model per mesh and warns once)
    kernels : the kernel back end of every solve of the model, ``"numpy"`` or ``"compiled"``
        (:func:`rftstatic.compiled.choose_kernels`); default: the self-contact law's, else the choice for
        this mesh. A constant of the run, recorded in its summary (``kernels``).
    """

    def __init__(self, mesh: TriMesh, material: Material, *, element="RFT6", supports=None, load=None,
                 contact=None, membrane=True, load_terms=(), quiet=False, self_contact=None, kernels=None):
        if element not in ELEMENTS:
            raise ValueError(f'unknown element "{element}"; use one of {", ".join(ELEMENTS)}')
        self.mesh = mesh
        self.material = material
        self.element = element
        self.supports = supports if supports is not None else Supports.none(mesh.n_nodes)
        self.load = np.zeros((mesh.n_nodes, 3)) if load is None else np.array(load, float)
        if self.load.shape != (mesh.n_nodes, 3):
            raise ValueError(f"load must have shape ({mesh.n_nodes}, 3), got {self.load.shape}")
        self.contact = contact
        self.self_contact = self_contact
        if self_contact is not None and kernels not in (None, self_contact.kernels):
            raise ValueError(f"kernels {kernels!r} differ from the self-contact law's {self_contact.kernels!r}: "
                             "build the law with the same kernels")
        self.kernels = (self_contact.kernels if self_contact is not None
                        else choose_kernels(mesh.n_elements, requested=kernels))
        self.load_terms = tuple(load_terms)
        self.with_membrane = bool(membrane)
        self.fixed = self.supports.fixed_mask()
        self.free = ~self.fixed
        self.patches = build_patches(mesh, clamped_nodes=self.supports.clamped)
        self.Kb = bending_stiffness(mesh, self.patches, material.Db)
        self.hinges = fold_hinges(mesh, material.Db)  # the creases of mesh.folds (rftstatic.element.hinge), or None
        self.membrane = membrane_operator(element, mesh, self.patches)
        h = material.hysteresis
        self.bending_friction = (None if h is None or h.M0_warp == h.M0_weft == 0.0 else bending_friction(
            self.patches, mesh.area, material.Db, warp_angle=np.radians(material.info.get("warp_angle_deg", 0.0)),
            M0=(h.M0_warp, h.M0_weft), ratio=h.ratio))
        nb = material.nonlinear_bending
        self.bending_softening = (None if nb is None or nb.k2_warp == nb.k2_weft == 0.0 else nonlinear_bending(
            self.patches, mesh.area, material.Db, warp_angle=np.radians(material.info.get("warp_angle_deg", 0.0)),
            k2=(nb.k2_warp, nb.k2_weft), floor=nb.floor))
        # both terms on one patch pass, compiled with the run's kernels (rftstatic.element.axis_terms)
        self.axis_terms = axis_terms(self.bending_friction, self.bending_softening,
                                     backend="numba" if self.kernels == "compiled" else "numpy")
        sh = material.shear_hysteresis
        self.shear_friction = (None if sh is None or sh.tau0 == 0.0 or not self.with_membrane else shear_friction(
            self.membrane, material.Dm, n_nodes=mesh.n_nodes,
            warp_angle=np.radians(material.info.get("warp_angle_deg", 0.0)), tau0=sh.tau0, ratio=sh.ratio,
            compiled=self.kernels == "compiled", tau5=sh.tau5))
        warnings = []
        if element == "RFT6" and self.with_membrane:
            lock = locking_number(mesh, material)
            if lock > LOCKING_WARN:
                h_ok = float(mesh.element_size.mean()) * np.sqrt(LOCKING_WARN / lock)
                text = (f"RFT6 membrane locking: (C/B) h^2 = {lock:.3g} > {LOCKING_WARN:.0e}; the averaged "
                        f"mid-side strains stiffen bending on this mesh (the wool strip of §4.1 bends 0.5 % too "
                        f"little at 2e4, 3.3 % at 8e4, 8 % at 8e5). Refine to a mean element size below {h_ok:.3g} m or use "
                        f'element = "RFT3"')
                warnings.append(text)
                # quiet: the caller has said it already (a remeshed run builds a model per remesh)
                log.log(logging.DEBUG if quiet else logging.WARNING, text)
        self.warnings = tuple(warnings)
        for a in (self.load, self.fixed, self.free):
            a.flags.writeable = False
        self._freeze()

    # --- constant structures, built on first use ------------------------------------------------
    @cached_property
    def plan(self) -> AssemblyPlan:
        couplings = [t.couplings() for t in (*self.load_terms, self.hinges) if hasattr(t, "couplings")]
        return AssemblyPlan(self.patches.nodes, self.mesh.n_nodes, self.free,
                            couplings=np.concatenate(couplings) if couplings else None)

    @cached_property
    def _bending_data(self) -> np.ndarray:
        return self.plan.scalar_kron_data(self.Kb)

    @cached_property
    def _membrane_map(self) -> np.ndarray:
        # contiguous: scatter_matrices ravels it at every tangent (a strided copy took 3 x the scatter)
        return np.ascontiguousarray(self.plan.element_map(self.membrane.nodes))

    @cached_property
    def _patch_map(self) -> np.ndarray:
        return np.ascontiguousarray(self.plan.element_map(self.patches.nodes))

    @property
    def X3(self) -> np.ndarray:
        """(N, 3) reference positions [m]."""
        return self.mesh.X3

    def bending_displacement(self, U) -> np.ndarray:
        """``(N, 3)`` [m]: what the curvature operator acts on (Eq. 7, 13). On a flat mesh ``U`` itself (L X = 0 for the
        flat reference, so L U = L x); on a sewn mesh (:attr:`rftstatic.mesh.trimesh.TriMesh.element_X`), whose
        placed reference is not flat across the seams, the positions ``X3 + U``: the bending energy is then
        ``1/2 x . K_b x``, zero for a garment lying flat across every seam, as its patches' unfolded reference."""
        return U if self.mesh.element_X is None else self.X3 + U

    def positions(self, U) -> np.ndarray:
        return self.X3 + U

    @property
    def membrane_backend(self) -> str:
        """The membrane operator's name of :attr:`kernels` (``"numba"`` or ``"numpy"``)."""
        return "numba" if self.kernels == "compiled" else "numpy"

    # --- energy and its derivatives -------------------------------------------------------------
    # ``candidates``: the solve's contact candidate list (a cache held in its State; results do not
    # depend on it), or None to evaluate the contact at every node; ``pairs``: likewise the solve's
    # self-contact pair cache (State.self_pairs), or None to find the pairs afresh; it also carries the
    # solve's factor on the self-contact stiffness (State.self_contact_scale; 1 without a cache), which
    # results do depend on; ``branches``: the potential loads' committed branches (State.load_branches).
    def energies(self, U, lam=1.0, *, candidates=None, pairs=None, branches=None, slip=None) -> dict:
        """Parts of the total potential [J]: bending, membrane, contact, self-contact, external work, total.
        ``bending`` holds the bending friction's incremental potential (:mod:`rftstatic.element.hysteresis`, H3)
        at the committed ``slip (E, 2)`` [1/m] (None: the virgin state), when the material has one."""
        Ub = self.bending_displacement(U)
        Eb = 0.5 * float(np.einsum("ni,ni->", Ub, self.Kb @ Ub))
        if self.axis_terms is not None:
            Eb += self.axis_terms.energy(Ub, self.positions(U), self.split_slip(slip)[0])
        if self.hinges is not None:
            Eb += self.hinges.energy(self.positions(U))
        Em = self.membrane.energy(U, self.material.Dm, backend=self.membrane_backend) if self.with_membrane else 0.0
        if self.shear_friction is not None:
            Em += self._shear(U, slip)[0]
        Ec = self.contact.energy(self.positions(U), candidates=candidates) if self.contact is not None else 0.0
        Es = (self.self_contact.evaluate(self.positions(U), tangent=False, cache=pairs).energy
              if self.self_contact is not None else 0.0)
        W = lam * float(np.einsum("ni,ni->", self.load, U))
        if self.load_terms:
            x = self.positions(U)
            held = branches or (None,) * len(self.load_terms)
            W -= lam * sum(t.potential(x, b) for t, b in zip(self.load_terms, held))
        return {"bending": Eb, "membrane": Em, "contact": Ec, "self_contact": Es, "external_work": W,
                "total": Eb + Em + Ec + Es - W}

    def potential(self, U, lam=1.0, *, candidates=None, pairs=None, branches=None, slip=None) -> float:
        """Total potential energy Pi(U) [J]."""
        return self.energies(U, lam, candidates=candidates, pairs=pairs, branches=branches, slip=slip)["total"]

    @property
    def has_friction(self) -> bool:
        """Whether the model has a friction term with a slip history (bending or shear hysteresis): its drape
        depends on the route."""
        return self.bending_friction is not None or self.shear_friction is not None

    def initial_slip(self) -> np.ndarray | None:
        """The virgin slips of the friction terms, ``(E, k)``: the bending friction's two columns [1/m] (when there
        is one), then the shear friction's one [-] (when there is one); None without either."""
        parts = [t.initial_slip() for t in (self.bending_friction, self.shear_friction) if t is not None]
        return np.concatenate(parts, axis=1) if parts else None

    def split_slip(self, slip) -> tuple:
        """``(bending (E, 2) or None, shear (E, 1) or None)``: the two frictions' columns of the slip array of
        :meth:`initial_slip` (None: the virgin state)."""
        slip = self.initial_slip() if slip is None else slip
        nb = 2 if self.bending_friction is not None else 0
        return (slip[:, :nb] if nb else None), (slip[:, nb:] if self.shear_friction is not None else None)

    def _shear(self, U, slip, tangent=False, psd=False):
        """The shear friction's energy [J], element forces (E, A, 3) [N] and tangents (E, A, 3, A, 3) [N/m]
        (:mod:`rftstatic.element.shear_friction`)."""
        return self.shear_friction.evaluate(U, self.split_slip(slip)[1], tangent=tangent, psd=psd)

    def commit_slip(self, U, slip) -> tuple[np.ndarray, float]:
        """Return mapping of the frictions at a converged ``U (N, 3)`` [m] from the committed ``slip (E, k)``
        (:meth:`initial_slip`): the new slip and the energy dissipated in the step [J] (:meth:`BendingFriction.commit
        <rftstatic.element.hysteresis.BendingFriction.commit>`, H4; :meth:`ShearFriction.commit
        <rftstatic.element.shear_friction.ShearFriction.commit>`, S6)."""
        bend, shear = self.split_slip(slip)
        parts, dissipated = [], 0.0
        if bend is not None:
            new, d = self.axis_terms.commit(self.bending_displacement(U), self.positions(U), bend)
            parts.append(new)
            dissipated += d
        if shear is not None:
            new, d = self.shear_friction.commit(U, shear)
            parts.append(new)
            dissipated += d
        return np.concatenate(parts, axis=1), dissipated

    def load_branches(self, U, previous=None) -> tuple:
        """The branch of each potential load at the converged ``U (N, 3)`` [m], continuous from ``previous``
        (None: the principal branches): what a solve commits to its ``State.load_branches`` after every
        converged increment (e.g. :meth:`rftstatic.model.loads.LeverMoment.branch`: angles tracked through
        full turns)."""
        x = self.positions(U)
        return tuple(t.branch(x, b) for t, b in zip(self.load_terms, previous or (None,) * len(self.load_terms)))

    def internal_force(self, U, *, candidates=None, pairs=None, slip=None) -> np.ndarray:
        """Internal (bending + membrane + contact + self-contact) force ``(N, 3)`` [N], the gradient of
        the stored energy (with the bending friction at the committed ``slip``, :meth:`energies`)."""
        f = self.Kb @ self.bending_displacement(U)
        if self.axis_terms is not None:
            self.axis_terms.add_forces(self.bending_displacement(U), self.positions(U), f, self.split_slip(slip)[0])
        if self.hinges is not None:
            f += self.hinges.force(self.positions(U))
        if self.with_membrane:
            fe = self.membrane.element_forces(U, self.material.Dm, backend=self.membrane_backend)
            if self.shear_friction is not None:
                fe = fe + self._shear(U, slip)[1]
            f += scatter_forces(self.membrane.nodes, fe, self.mesh.n_nodes)
        if self.contact is not None:
            f += self.contact.force(self.positions(U), candidates=candidates)
        if self.self_contact is not None:
            f += self.self_contact.evaluate(self.positions(U), tangent=False, cache=pairs).force
        return f

    def residual(self, U, lam=1.0, *, candidates=None, pairs=None, slip=None) -> np.ndarray:
        """Out-of-balance force ``dPi/dU (N, 3)`` [N]; zero at equilibrium on the free dofs."""
        r = self.internal_force(U, candidates=candidates, pairs=pairs, slip=slip) - lam * self.load
        for term in self.load_terms:
            r += lam * term.force(self.positions(U))
        return r

    def tangent(self, U, *, psd=False, shift=0.0, lam=1.0, candidates=None, stress=None, pairs=None, slip=None):
        """Internal force ``(N, 3)`` [N] and tangent of the free dofs (CSR) [N/m] at load factor ``lam``.

        ``psd=True`` drops compressive stress from the geometric stiffness (positive semi-definite
        membrane tangent); ``shift`` adds ``shift * I`` (Levenberg-Marquardt); ``stress (E, 3)``
        [N/m]: the membrane stress of the geometric stiffness (MIP Newton's mixed stress,
        :meth:`mixed_stress`) in place of :meth:`membrane_stress` (None: the exact Hessian).

        Self-contact couples nodes outside the patch pattern: its PSD pair blocks are added as a second
        sparse matrix (:meth:`_pair_matrix`), so the pattern of the result changes with the pairs in
        contact (a sparse factorisation must redo its symbolic analysis then). The bending friction (at the
        committed ``slip``, :meth:`energies`) adds its consistent tangent on the patch pattern.
        """
        plan = self.plan
        data = self._bending_data.copy()
        f = self.Kb @ self.bending_displacement(U)
        x = self.positions(U)
        if self.axis_terms is not None:  # bending friction and softening
            fe = self.axis_terms.add_tangents(self.bending_displacement(U), x, self._patch_map, data,
                                                  self.split_slip(slip)[0], psd=psd)
            f += scatter_forces(self.patches.nodes, fe, self.mesh.n_nodes)
        if self.hinges is not None:
            fh, (rows, cols, blocks) = self.hinges.force_tangent_blocks(x, psd=psd)
            f += fh
            data += scatter_matrices(plan.positions(rows, cols), blocks, plan.nnz)
        if self.with_membrane:
            fe = self.membrane.tangents_into(U, self.material.Dm, self._membrane_map, data, psd=psd, stress=stress,
                                             backend=self.membrane_backend)
            if self.shear_friction is not None:
                _, fs, ks = self._shear(U, slip, tangent=True, psd=psd)
                fe = fe + fs
                data += scatter_matrices(self._membrane_map, ks, plan.nnz)
            f += scatter_forces(self.membrane.nodes, fe, self.mesh.n_nodes)
        if self.contact is not None:
            cs = self.contact.evaluate(x, candidates=candidates)
            f += cs.force
            data += scatter_matrices(plan.diag_positions, cs.tangent_blocks, plan.nnz)
            if cs.pair_blocks is not None:  # an obstacle's sharp features against sheet edges and triangles
                rows, cols, blocks = cs.pair_blocks
                data += scatter_matrices(plan.positions(rows, cols), blocks, plan.nnz)
        for term in self.load_terms:  # load stiffness of potential loads (not part of f)
            rows, cols, blocks = term.tangent_blocks(x)
            data += scatter_matrices(plan.positions(rows, cols), lam * blocks, plan.nnz)
        if shift:
            data += scatter_matrices(plan.diag_positions, shift * np.broadcast_to(np.eye(3), (self.mesh.n_nodes, 3, 3)), plan.nnz)
        K = plan.free_matrix(data)
        if self.self_contact is not None:
            ss = self.self_contact.evaluate(x, tangent=True, cache=pairs)
            f += ss.force
            if ss.n_active:
                K = K + self._pair_matrix(ss.nodes, ss.blocks)
                K.sort_indices()
        return f, K

    @cached_property
    def _free_index(self) -> np.ndarray:
        """(3N,) index of each dof among the free dofs, -1 for a prescribed one."""
        idx = np.full(3 * self.mesh.n_nodes, -1, dtype=np.int64)
        idx[self.plan.free_dofs] = np.arange(len(self.plan.free_dofs))
        return idx

    def _pair_matrix(self, nodes, blocks):
        """CSR of the free dofs [N/m] summing pair blocks ``blocks (A, 12, 12)`` over ``nodes (A, 4)``."""
        import scipy.sparse as sp

        dof = self._free_index[(3 * nodes[:, :, None] + np.arange(3)).reshape(-1, 12)]  # (A, 12)
        r = np.repeat(dof, 12, axis=1).ravel()
        c = np.tile(dof, (1, 12)).ravel()
        keep = (r >= 0) & (c >= 0)
        n = len(self.plan.free_dofs)
        return sp.csr_matrix((blocks.ravel()[keep], (r[keep], c[keep])), shape=(n, n))

    # --- post-processing ------------------------------------------------------------------------
    def curvature(self, U) -> np.ndarray:
        """(E, 3) element curvature (k_xx, k_yy, 2 k_xy) [1/m], Eq. 7."""
        return curvature(self.patches, self.bending_displacement(U), self.positions(U))

    def membrane_strain(self, U) -> np.ndarray:
        """(E, 3) averaged Green membrane strain (e_xx, e_yy, 2 e_xy) [-]."""
        return self.membrane.strain(U)

    def membrane_stress(self, U) -> np.ndarray:
        """(E, 3) membrane stress resultant ``S = D^m eps(U)`` (S_xx, S_yy, S_xy) [N/m], Eq. 15."""
        return self.membrane.strain(U) @ self.material.Dm.T

    def mixed_stress(self, U, dU) -> np.ndarray:
        """(E, 3) stress of the linearised strain ``D^m (eps(U) + Bbar(U) dU)`` [N/m]: the membrane stress
        that MIP Newton carries from ``U`` over the step ``dU (N, 3)`` [m] (:mod:`rftstatic.solvers.newton`)."""
        return self.membrane.linearised_strain(U, dU, backend=self.membrane_backend) @ self.material.Dm.T

    def relative_curvature(self, U) -> np.ndarray:
        """(E,) |kappa| h, the relative curvature of §2.2 and §5.1 [-].

        |kappa| [1/m] is :func:`rftstatic.element.curvature.curvature_norm` of :meth:`curvature`,
        h [m] the mean side length (``mesh.element_size``).
        """
        return curvature_norm(self.curvature(U)) * self.mesh.element_size

