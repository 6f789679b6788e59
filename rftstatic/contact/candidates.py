"""Candidate lists: the nodes near an obstacle, so that a step pays only for them.

A signed distance changes no faster than the point moves (it is 1-Lipschitz). When the list is made,
every point's distance ``phi`` is computed and the candidates are the points with ``phi < margin``.
Until some point has moved more than ``margin / 2`` since then, every other point is still more than
``margin / 2`` from the obstacles, so only the candidates need their distance: the contact computed
with the list is the same as without it. The list is a cache of the solve (it lives in the
:class:`~rftstatic.model.state.State`, not in the Model) and never changes a result.

It also carries the one thing of the contact that is not a cache, the obstacles' poses in this solve
(:attr:`CandidateList.poses`, :class:`rftstatic.contact.motion.Poses`: a rotation and translation per obstacle, e.g.
a body turned by its keyframes; :attr:`CandidateList.offsets`: translations only, e.g. a support lowered by a
route), as the self-contact pair cache carries the solve's stiffness scale: every contact evaluation receives the
list. With moved obstacles the list measures the motion of the points in every obstacle's body frame (the
distance to obstacle ``m`` is 1-Lipschitz in ``y_m = R_m^T (x - c_m - s_m) + c_m``), so a turning body and a
swinging sheet refresh it only once their relative motion reaches ``margin / 2``.
"""

from __future__ import annotations

import numpy as np

from rftstatic.contact.motion import Poses


class CandidateList:
    """The points within ``margin`` [m] of the obstacles at the last refresh.

    Parameters
    ----------
    margin : candidate distance [m]; a few contact onset widths, or a fraction of a node spacing
    """

    def __init__(self, margin: float):
        self.margin = float(margin)
        self.refreshes = 0
        self._indices = None  # (C,) candidate indices
        self._x = None  # (N, 3) positions at the refresh [m], (M, N, 3) in the obstacles' body frames if moved
        self._gap = None  # (N,) distances at the refresh [m]
        self.pairs = None  # a law's pair list and the positions it was built at (rftstatic.contact.features)
        self.friction = None  # the solve's lagged friction (State.contact_history["friction"], rftstatic.contact.friction)
        self._poses = None  # the obstacles' poses in this solve (rftstatic.contact.motion.Poses); None: as built
        self._shape_ref = None  # (M,) deforming obstacles' shape times at the refresh [s]

    @property
    def poses(self) -> Poses | None:
        """The poses of the contact law's ``M`` obstacles in this solve (obstacle ``m`` is evaluated in its body
        frame, :mod:`rftstatic.contact.motion`); None: every obstacle where it was built. Setting it keeps the list
        (its validity is measured in the body frames)."""
        return self._poses

    @poses.setter
    def poses(self, value) -> None:
        if value is not None and not isinstance(value, Poses):
            raise ValueError(f"obstacle poses must be a rftstatic.contact.motion.Poses or None, got {value!r}")
        self._poses = None if value is None or value.at_rest else value

    @property
    def offsets(self) -> np.ndarray | None:
        """``(M, 3)`` translation [m] of each of the contact law's ``M`` obstacles from its built pose in this
        solve (the translation part of :attr:`poses`; obstacle ``m`` at rest is evaluated at ``x - offsets[m]``);
        None: every obstacle where it was built. Setting it sets translation-only poses and, when they change,
        makes the list again."""
        return None if self._poses is None else np.array(self._poses.translation)

    @offsets.setter
    def offsets(self, value) -> None:
        new = None if value is None else np.array(value, dtype=float)
        if new is not None and (new.ndim != 2 or new.shape[1] != 3 or not np.isfinite(new).all()):
            raise ValueError(f"obstacle offsets must be a finite (M, 3) array [m], got {value!r}")
        if new is not None and not new.any():
            new = None
        old = self.offsets
        same = (new is None and old is None) or (new is not None and old is not None and np.array_equal(new, old)
                                                 and not self._poses.rotated)
        if not same:  # the distances at the last refresh are the old pose's: make the list again
            self._poses = None if new is None else Poses.translations(new)
            self.reset()

    def reset(self, margin: float | None = None) -> None:
        """Forget the list (e.g. a new mesh); optionally a new ``margin`` [m]."""
        if margin is not None:
            self.margin = float(margin)
        self._indices = self._x = self._gap = self.pairs = self._shape_ref = None

    @property
    def shape_times(self) -> np.ndarray | None:
        """``(M,)`` the deforming obstacles' shape times [s] at the last refresh (NaN: rigid), or None."""
        return self._shape_ref

    def lookup(self, x: np.ndarray, slack: float = 0.0):
        """``(indices (C,), lower bounds (N,) of every point's distance [m])`` while the list is valid for
        positions ``x (N, 3)`` [m], else None (refresh it: :meth:`refresh`). The bounds are exact
        values at the refresh minus the largest motion since (plus ``slack`` [m], the largest motion of a
        deforming obstacle's surface since); callers fill in the candidates' exact distances."""
        if self._x is None or self._x.shape[-2:] != x.shape:
            return None
        d = self._frames(x) - self._x
        moved = float(np.sqrt(np.max(np.einsum("...i,...i->...", d, d), initial=0.0))) + slack
        if moved > 0.5 * self.margin:
            return None
        return self._indices, self._gap - moved

    def refresh(self, x: np.ndarray, gap: np.ndarray) -> np.ndarray:
        """Make the list from every point's distance ``gap (N,)`` [m] at ``x (N, 3)`` [m]; return the indices."""
        self._indices = np.flatnonzero(gap < self.margin)
        self._x = np.array(self._frames(x), dtype=float, copy=True)
        self._shape_ref = None if self._poses is None else np.array(self._poses.shape_time)
        self._gap = np.array(gap, dtype=float, copy=True)
        self.refreshes += 1
        return self._indices

    def _frames(self, x):
        """The positions ``x (N, 3)`` [m] the list measures motion in: ``x`` itself, or with moved obstacles
        ``(M, N, 3)`` in every obstacle's body frame."""
        return x if self._poses is None else self._poses.body_frames(x)

    @property
    def gaps(self) -> np.ndarray | None:
        """``(N,)`` every point's distance [m] at the last refresh (None before one)."""
        return self._gap

    @property
    def reference(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """``(positions (N, 3) [m] (``(M, N, 3)`` in the body frames with :attr:`poses`), indices (C,), distances
        (N,) [m])`` at the last refresh, what :meth:`lookup` tests and returns (the compiled twin of its test and of
        the penalty's filter, :mod:`rftstatic.contact.penalty_compiled`, reads them); None before a refresh."""
        return None if self._x is None else (self._x, self._indices, self._gap)

    def __len__(self) -> int:
        return 0 if self._indices is None else len(self._indices)
