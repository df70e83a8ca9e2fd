"""Tests of drakecreep.paper.hertz against closed-form and independent Hertz solutions."""

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.paper.hertz import (BEARING_STEEL, TABLE3_NUT, BallScrewNut, ballscrew_stiffness,
                              brewe_hamrock_contact, point_contact)

E, NU = 2.0e11, 0.3


def test_sphere_on_flat_matches_hertz_closed_form():
    """Hertz: delta = (9 P^2 / (16 E*^2 R))^(1/3), a = (3 P R / (4 E*))^(1/3), 1/E* = sum (1-nu^2)/E."""
    R, P = 5e-3, 100.0
    steel = type(BEARING_STEEL)(E, NU)
    c = point_contact(P, (1 / R, 1 / R, 0.0, 0.0), steel, steel)
    e_star = 1.0 / (2 * (1 - NU**2) / E)
    assert c.approach == pytest.approx((9 * P**2 / (16 * e_star**2 * R)) ** (1 / 3), rel=1e-9)
    assert c.a == pytest.approx((3 * P * R / (4 * e_star)) ** (1 / 3), rel=1e-9)
    assert c.coefficients.kappa == pytest.approx(1.0)


def test_crossed_equal_cylinders_equal_sphere_on_flat():
    """Two equal cylinders crossed at 90 deg behave like a sphere of the same radius on a flat."""
    R, P = 10e-3, 500.0
    crossed = point_contact(P, (1 / R, 0.0, 0.0, 1 / R))
    sphere = point_contact(P, (1 / R, 1 / R, 0.0, 0.0))
    assert crossed.approach == pytest.approx(sphere.approach, rel=1e-9)


def test_209_bearing_inner_race_against_brewe_hamrock():
    """Deep-groove 209 bearing, ball-inner race contact, geometry of the worked example in
    Hamrock, Schmid & Jacobson, *Fundamentals of Machine Elements* (ch. on rolling-element bearings):
    d = 12.7 mm, inner race diameter 52.291 mm, groove radius 6.604 mm, E = 200 GPa, nu = 0.3;
    ball load 5 Fr / Z (Stribeck) with Fr = 8900 N, Z = 9. Cross-checked against the Brewe-Hamrock
    (1977) closed forms, which agree with the exact elliptic-integral solution to a few percent."""
    d, di, ri = 12.7e-3, 52.291e-3, 6.604e-3
    P = 5 * 8900.0 / 9
    steel = type(BEARING_STEEL)(E, NU)
    exact = point_contact(P, (2 / d, 2 / d, 2 / di, -1 / ri), steel, steel)
    Rx = 1 / (2 / d + 2 / di)
    Ry = 1 / (2 / d - 1 / ri)
    approx = brewe_hamrock_contact(P, Rx, Ry, 2 / (2 * (1 - NU**2) / E))
    assert exact.coefficients.kappa == pytest.approx(approx["kappa"], rel=0.03)
    assert exact.approach == pytest.approx(approx["approach"], rel=0.03)
    assert exact.a == pytest.approx(approx["a"], rel=0.03)
    assert exact.b == pytest.approx(approx["b"], rel=0.03)


def test_tangent_stiffness_equals_numerical_derivative():
    nut = TABLE3_NUT
    r0 = ballscrew_stiffness(nut)
    h = 1e-3 * nut.preload
    da = (ballscrew_stiffness(nut, nut.preload + h).axial_deflection
          - ballscrew_stiffness(nut, nut.preload - h).axial_deflection)
    assert r0.ka_tangent == pytest.approx(2 * h / da, rel=1e-5)
    assert r0.ka_tangent == pytest.approx(1.5 * r0.ka_secant)


def test_table3_case_ball_load_helix_and_frequency_relation():
    r = ballscrew_stiffness()
    assert np.degrees(r.helix) == pytest.approx(3.6426, abs=1e-4)
    assert r.ball_load == pytest.approx(579 / (47 * np.sin(np.pi / 4) * np.cos(r.helix)))
    assert r.fa == pytest.approx(np.sqrt(r.ka_tangent / 0.335) / (2 * np.pi))
    # the nut contact (concave along the helix) is more conformal: smaller deformation
    assert r.nut_contact.approach < r.screw_contact.approach
    # paper's eq. 16 ratio: Kr/Ka = tan(lambda)/tan(beta) for the same Fa
    assert r.kr_paper_tangent / r.ka_tangent == pytest.approx(np.tan(r.helix), rel=1e-12)


def test_bad_geometry_raises_input_error():
    with pytest.raises(InputError):
        BallScrewNut(conformity=0.9)
    with pytest.raises(InputError):
        point_contact(-1.0, (1.0, 1.0, 0.0, 0.0))


@pytest.mark.parametrize("degrees", [1e-300, 0.1, 4.9, 85.1])
def test_a_contact_angle_outside_a_ball_screws_is_refused_by_name(degrees):
    """A contact angle of 1e-300 deg loaded each ball with 7e302 N; the contact that then left the ball was
    refused as 'conformity: got 1.04', a field nobody had set."""
    import dataclasses

    with pytest.raises(InputError, match=r"^contact_angle: got .*; allowed: in \[0.08727, 1.484\] rad \(5 to 85 deg"):
        dataclasses.replace(TABLE3_NUT, contact_angle=float(np.radians(degrees)))
    for edge in (5.0, 85.0):
        assert ballscrew_stiffness(dataclasses.replace(TABLE3_NUT, contact_angle=float(np.radians(edge)))).fa > 0


def test_a_contact_longer_than_the_ball_is_refused():
    """Hertz theory needs a contact small against the ball: a groove a hair wider than the ball gave a 314 mm
    ellipse on a 3.175 mm ball, and an axial stiffness 1900 times the paper's."""
    import dataclasses

    with pytest.raises(InputError, match=r"conformity: .*semi-major axis is [0-9.]+ mm .*beyond the ball's radius"):
        ballscrew_stiffness(dataclasses.replace(TABLE3_NUT, conformity=1.0001))
    near = ballscrew_stiffness(dataclasses.replace(TABLE3_NUT, conformity=1.001))  # a long contact, still inside
    assert 0.5 * TABLE3_NUT.ball_diameter > float(near.screw_contact.a) > 0.3 * TABLE3_NUT.ball_diameter


def test_the_load_limit_of_a_contact_is_where_it_reaches_the_ball():
    """The refusal's axial force limit (a grows as P^(1/3)) is the edge: just below it the contact fits the ball,
    just above it it does not (the CLI's '--preload' refusal quotes it)."""
    import dataclasses

    with pytest.raises(InputError) as err:
        ballscrew_stiffness(TABLE3_NUT, axial_force=1e7)
    limit = err.value.load_limit
    assert 1e3 < limit < 1e7 and f"an axial force below {limit:.4g} N" in str(err.value)
    inside = ballscrew_stiffness(TABLE3_NUT, axial_force=0.999 * limit)
    assert float(inside.screw_contact.a) == pytest.approx(0.5 * TABLE3_NUT.ball_diameter, rel=1e-3)
    with pytest.raises(InputError):
        ballscrew_stiffness(dataclasses.replace(TABLE3_NUT), axial_force=1.001 * limit)
