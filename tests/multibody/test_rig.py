"""The paper's joint tables in SI and the series / face helpers."""

import math

import pytest

from drakecreep.multibody.rig import RigGeometry, face_joint, paper_joints, series, series_damping


def test_paper_joints_in_si():
    j = paper_joints()
    assert j["screw-nut"].kt == 51.6e6 and j["screw-nut"].ct == 898.88  # Table 4, axial
    assert j["bearing"].kn == 5.02e6  # Table 6, radial
    assert j["guide-slider"].kn == 52.3e6 and j["guide-slider"].kt == 55.2e6  # Table 5 vertical / lateral
    assert j["base-bearing seat"].kn == pytest.approx(12.15e10)  # Table 1, 1e10 N/m
    assert j["inner ring-screw shaft"].kt == pytest.approx(0.22e10)  # Table 2, axial
    assert j["nut-nut seat"].cn == pytest.approx(1.360e5)  # Table 1, 1e8 N s/m


def test_series_and_its_damping():
    assert series(2.0, 2.0) == pytest.approx(1.0)
    assert series(3.0, math.inf) == 3.0
    assert series(3.0, 0.0) == 0.0
    # equal loss factors c/k: the chain keeps it
    assert series_damping([(2.0, 0.2), (2.0, 0.2)]) == pytest.approx(0.1)
    assert series_damping([(2.0, 0.2), (math.inf, 5.0)]) == pytest.approx(0.2)


def test_face_joint_rocking_and_twist():
    torque, force = face_joint(12.0, 3.0, 2, (2.0, 1.0))  # normal z, 2 m along x, 1 m along y
    assert force == [3.0, 3.0, 12.0]
    assert torque[0] == pytest.approx(12.0 * 1.0**2 / 12.0)  # about x: the side across is y
    assert torque[1] == pytest.approx(12.0 * 2.0**2 / 12.0)
    assert torque[2] == pytest.approx(3.0 * 5.0 / 12.0)


def test_rig_defaults_are_valid_and_fields_documented():
    rig = RigGeometry()
    from dataclasses import fields

    for f in fields(rig):
        assert "[assumed]" in f.metadata["doc"], f.name
