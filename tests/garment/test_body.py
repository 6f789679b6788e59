"""The parametric dress form: a closed, outward-wound surface whose sections have the measured girths."""

import numpy as np
import pytest

from rftstatic.garment.body import DressForm, ellipse_perimeter, semi_axes
from rftstatic.mesh.surface import check_triangles

# example measurements of a woman about 1.68 m tall (not a size chart: the size tables come later)
EXAMPLE = dict(bust_girth=0.88, waist_girth=0.70, hip_girth=0.96, bust_height=1.22, waist_height=1.05,
               hip_height=0.86, shoulder_breadth=0.38, shoulder_height=1.37, neck_girth=0.34, neck_height=1.42)


def test_the_ellipse_perimeter_is_exact_for_a_circle_and_matches_quadrature():
    assert ellipse_perimeter(1.0, 1.0) == pytest.approx(2 * np.pi, rel=1e-15)
    t = np.linspace(0.0, 2 * np.pi, 200_001)
    for ratio in (0.4, 0.7, 0.95):
        a, b = semi_axes(1.0, ratio)
        f = np.hypot(a * np.sin(t), b * np.cos(t))
        numeric = float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(t)))  # trapezoid rule
        assert numeric == pytest.approx(1.0, rel=1e-8) and b / a == pytest.approx(ratio)


def test_the_surface_is_a_closed_outward_wound_manifold():
    P, tri = DressForm(**EXAMPLE).surface()
    info = check_triangles(P, tri, where="dress form", oriented=True)
    assert info["closed"]
    assert len(P) - len(info["edges"]) + len(tri) == 2  # a sphere's Euler characteristic
    a, b, c = P[tri[:, 0]], P[tri[:, 1]], P[tri[:, 2]]
    volume = np.einsum("ij,ij->", a, np.cross(b, c)) / 6.0  # positive: the normals point outwards
    assert volume > 0


@pytest.mark.parametrize("around,tol", [(64, 1e-3), (256, 1e-4)])
def test_the_sections_have_the_measured_girths_at_their_heights(around, tol):
    form = DressForm(**EXAMPLE)
    for name in ("bust", "waist", "hip", "neck"):
        z = EXAMPLE[f"{name}_height"] + (form.neck_fillet() if name == "neck" else 0.0)  # above the neck's fillet
        assert form.girth(z, around=around) == pytest.approx(EXAMPLE[f"{name}_girth"], rel=tol), name
    a, _ = form.section(np.array([EXAMPLE["shoulder_height"]]))
    assert 2 * a[0] == pytest.approx(EXAMPLE["shoulder_breadth"], rel=1e-12)


def test_the_shoulder_turns_into_the_neck_without_a_crease():
    # the profile a(z) from the shoulder's top into the neck is C1: its direction turns smoothly from horizontal
    # (the shoulder's top) to vertical (the neck) along the fillet (a right-angled crease before the fillet)
    form = DressForm(**EXAMPLE)
    zn, rho = EXAMPLE["neck_height"], form.neck_fillet()
    z = np.linspace(zn - 0.02, zn + rho + 0.01, 4001)
    a, _ = form.section(z)
    turn = np.abs(np.diff(np.arctan2(np.diff(z), np.diff(a))))  # [rad] between consecutive chords
    length = np.hypot(np.diff(z), np.diff(a))
    assert np.max(turn / (0.5 * (length[1:] + length[:-1]))) < 1.0 / (0.5 * rho)  # curvature: no crease
    # the fillet: a quarter circle of radius rho from rho outside the neck to the neck, rho higher
    assert form.section(np.array([zn]))[0][0] == pytest.approx(form.section(np.array([zn + rho]))[0][0] + rho)


def test_the_form_is_a_mesh_obstacle(tmp_path):
    from rftstatic.contact.obstacles import SurfaceObstacle

    path = tmp_path / "form.obj"
    DressForm(**EXAMPLE).write_obj(path)
    ob = SurfaceObstacle(path, units="m")
    a, _ = semi_axes(EXAMPLE["waist_girth"], 0.74)
    x = np.array([[0.0, 0.0, EXAMPLE["waist_height"]], [a + 0.01, 0.0, EXAMPLE["waist_height"]]])
    phi, normal = ob.signed_distance(x)
    assert phi[0] < 0 < phi[1]
    # 1 cm outside the waist along x: the narrowest section, so its nearest surface point is at most 1 cm away
    assert 0.009 < phi[1] <= 0.01 + 1e-6 and normal[1][0] > 0.95


@pytest.mark.parametrize("change,fragment", [
    ({"waist_height": 1.30}, "bust height"),  # the waist above the bust
    ({"hip_girth": -0.9}, "hip_girth"),
    ({"bust_depth": 0.2}, "bust_depth"),
    ({"shoulder_breadth": 0.05}, "shoulder breadth"),
])
def test_bad_measurements_are_refused_naming_them(change, fragment):
    with pytest.raises(ValueError, match=fragment):
        DressForm(**{**EXAMPLE, **change})
