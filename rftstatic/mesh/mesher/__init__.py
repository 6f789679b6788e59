"""Two-dimensional advancing-front triangle mesher (Lo & Lee 1994 family).

Used by the global adaptive remeshing of Sze & Zhou (2016), section 5.2 g:
a new mesh of the flat reference domain is generated from the target sizes
h_target (Eq. 29) stored on a square background grid.

Public API
----------
``Domain``
    Outer loop plus holes: ``Domain.rectangle(x0, y0, lx, ly)``,
    ``Domain.disc(cx, cy, r)``, ``Domain.annulus(cx, cy, r_in, r_out)``,
    ``Domain.polygon(outer, holes=())`` and
    ``Domain.from_segments(points, segments)`` (e.g. an old mesh boundary).
``BackgroundGrid(origin, spacing, values, gradation=None)``
    Size field [m] with bilinear ``size_at(points)``; constructors
    ``uniform(h, region)``, ``from_function(h, region, ...)`` and
    ``from_samples(points, sizes, region, ...)``, all with a gradation limit
    (see :mod:`rftstatic.mesh.mesher.sizefield`).
``generate(domain, size_field, *, smooth_iterations=4) -> MeshResult``
    ``.points`` (N, 2) float64 [m], ``.triangles`` (E, 3) int64
    counter-clockwise, ``.boundary`` (N,) bool, ``.boundary_edges`` (B, 2),
    ``.quality`` (:class:`MeshQuality`, with ``as_dict()``).
    Deterministic: the same input gives the same mesh.
``MeshingError``
    ``ValueError`` subclass for bad input and fronts that cannot close.

Pipeline: discretise the loops from the size field (corners kept, circle
nodes on the circle) -> advancing front (:mod:`.front`) -> Delaunay flips,
constrained Laplacian smoothing, local optimisation of the worst nodes
(:mod:`.improve`) -> quality figures (:mod:`.quality`).
``python -m rftstatic.bench.mesher`` times meshes of 2k, 20k and 200k nodes.
"""

from rftstatic.errors import MeshingError
from rftstatic.mesh.mesher.domain import Domain, Loop
from rftstatic.mesh.mesher.generate import MeshResult, generate
from rftstatic.mesh.mesher.quality import MeshQuality, measure_quality
from rftstatic.mesh.mesher.sizefield import BackgroundGrid

__all__ = ["Domain", "Loop", "BackgroundGrid", "generate", "MeshResult", "MeshQuality",
           "measure_quality", "MeshingError"]
