"""What a meshed pattern is, in lines a person reads: panels, seams and mesh quality (``python -m rftstatic
pattern FILE``). Lengths are printed in centimetres, the unit of pattern making."""

from __future__ import annotations

import numpy as np

__all__ = ["describe"]


def describe(pmesh) -> str:
    """The panels (edges, area, nodes, triangles, smallest angle), the seams (kind, edges, node pairs, the
    length difference of their two sides) and the totals of a :class:`~rftstatic.garment.meshing.PatternMesh`."""
    pat = pmesh.pattern
    lines = [f"pattern {pat.source}: {len(pat.panels)} panels, {len(pat.seams)} seams, element size "
             f"{100 * pmesh.h:g} cm",
             "", f"{'panel':<16} {'edges':>5} {'area [cm^2]':>12} {'nodes':>7} {'triangles':>9} {'min angle':>9}"]
    for panel, m, q in zip(pat.panels, pmesh.meshes, pmesh.quality):
        area = float(m.area.sum()) * 1e4
        lines.append(f"{panel.name:<16} {len(panel.edges):>5} {area:>12.1f} {m.n_nodes:>7} {m.n_elements:>9} "
                     f"{q.min_angle:>8.1f}°")
    if pat.seams:
        lines += ["", f"{'seam':<34} {'kind':<5} {'pairs':>6} {'length A / B [cm]':>20}"]
        for s, pairs in zip(pat.seams, pmesh.seam_pairs):
            la = pat.panels[pat.index[s.a_panel]].edge_length(s.a_edge)
            lb = pat.panels[pat.index[s.b_panel]].edge_length(s.b_edge)
            name = f"{s.a_panel}:{s.a_edge} - {s.b_panel}:{s.b_edge}"
            lines.append(f"{name:<34} {s.kind:<5} {len(pairs):>6} {100 * la:>9.2f} / {100 * lb:.2f}")
    n_el = sum(m.n_elements for m in pmesh.meshes)
    angle = min(q.min_angle for q in pmesh.quality)
    sewn = int(sum(len(p) for p in pmesh.seam_pairs))
    lines += ["", f"{pmesh.n_nodes} nodes, {n_el} triangles, {sewn} seam node pairs, smallest angle "
              f"{angle:.1f}°; panels placed apart (no overlap at the start)"]
    return "\n".join(lines)

