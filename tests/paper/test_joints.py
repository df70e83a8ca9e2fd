"""Tests of drakecreep.paper.joints: Yoshimura integral, bolt and interference-fit models, Tables 1-2."""

import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.paper.joints import (EXAMPLE_GROUND_STEEL, BoltedFace, InterferenceFit, PowerLaw,
                               UnitAreaJoint, bolted_joint, interference_fit_joint,
                               lame_interference_pressure, table1_ratios, table2_ratios,
                               yoshimura_integral)
from drakecreep.paper.tables import read_paper_table


def test_linear_law_integral_depends_only_on_total_load():
    """With k proportional to p, the integral of k dA is alpha * total load, whatever the distribution."""
    linear = PowerLaw(2e12, 1.0)
    unit = UnitAreaJoint(linear, linear, linear, linear, "test")
    face = BoltedFace(area=0.05, bolts=4, preload=10e3)
    values = [bolted_joint(face, unit, d).kn for d in ("uniform", "cone-uniform", "cone-linear")]
    np.testing.assert_allclose(values, 2e12 * 40e3 / 1e6, rtol=1e-8)


def test_concave_law_penalises_concentrated_pressure():
    """beta < 1: spreading the same load wider gives a stiffer joint (Jensen's inequality)."""
    face = BoltedFace(area=0.05, bolts=4, preload=10e3)
    k = {d: bolted_joint(face, EXAMPLE_GROUND_STEEL, d).kn for d in ("uniform", "cone-uniform",
                                                                     "cone-linear")}
    assert k["uniform"] > k["cone-uniform"] > k["cone-linear"]


def test_yoshimura_integral_discrete_sum():
    law = PowerLaw(1.0, 0.5, reference_pressure=1.0)
    assert yoshimura_integral(law, [4.0, 9.0, 0.0], [1.0, 2.0, 5.0]) == pytest.approx(2 + 6)


def test_lame_pressure_solid_shaft_equal_materials():
    """Same material, solid shaft: p = E delta (do^2 - d^2) / (2 d do^2) (Shigley)."""
    fit = InterferenceFit(diameter=20e-3, length=15e-3, interference=15e-6, hub_outer_diameter=40e-3)
    d, do = 20e-3, 40e-3
    assert lame_interference_pressure(fit) == pytest.approx(
        2.06e11 * 15e-6 * (do**2 - d**2) / (2 * d * do**2), rel=1e-12)
    joint = interference_fit_joint(fit)
    assert joint.contact_area == pytest.approx(np.pi * d * 15e-3)
    assert joint.kn > joint.kt  # radial (normal-dominated) stiffer than axial (shear)


def test_table1_every_column_is_proportional_to_kn():
    r = table1_ratios(read_paper_table("table1_bolted_fixed_joints"))
    for key in ("cn_over_kn_s", "kt_over_kn", "ct_over_kn_s"):
        spread = np.ptp(r[key]) / np.mean(r[key])
        assert spread < 0.005, key  # the same ratio in every row, to print rounding (<0.5 %)
    assert np.mean(r["cn_over_kn_s"]) == pytest.approx(1.737e-6, rel=2e-3)


def test_table2_damping_proportional_to_stiffness_but_not_kr_to_ka():
    r = table2_ratios(read_paper_table("table2_interference_fit_joints"))
    np.testing.assert_allclose(r["cr_over_kr_s"], 1e-3, rtol=1e-6)
    np.testing.assert_allclose(r["ca_over_ka_s"], 2.5e-5, rtol=2e-3)
    assert r["kr_over_ka"][1] / r["kr_over_ka"][0] > 1.5  # different geometry ratio per row


def test_bad_face_raises_input_error():
    with pytest.raises(InputError):
        BoltedFace(area=-1.0, bolts=4, preload=1e3)
    with pytest.raises(InputError):
        bolted_joint(BoltedFace(area=0.05, bolts=4, preload=1e3), distribution="parabolic")


def test_axial_path_joints_from_tables_1_and_2():
    from drakecreep.paper.joints import axial_path_joints

    j = axial_path_joints()
    kbs, cbs = j["bearing_seat"]
    # 12.15e10 (base-seat), 0.643e10 (seat-outer ring), 0.22e10 (inner ring-shaft) N/m in series
    assert kbs == pytest.approx(1 / (1 / 12.15e10 + 1 / 0.643e10 + 1 / 0.22e10))
    kns, _ = j["nut_seat"]
    assert kns == pytest.approx(1 / (1 / 11.07e10 + 1 / 7.83e10))
    assert cbs > 0
