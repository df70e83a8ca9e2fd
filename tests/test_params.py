import math

import pytest

from drakecreep.errors import InputError
from drakecreep.params import (
    DriveParams, LoadCase, LoadParams, get_value, load_params, params_from_dict, params_to_dict, preset, preset_text,
    save_params, with_value,
)


def test_paper_preset_carries_the_paper_values(paper):
    assert paper.screw.lead == 5e-3 and paper.screw.nominal_diameter == 25e-3
    assert paper.nut.axial_stiffness == 51.6e6 and paper.nut.axial_damping == 898.88
    assert paper.screw.bearing_stiffness == 9.38e6
    assert [(c.fx, c.fy, c.fz) for c in paper.loads.cases] == [(174, 151, 524), (252, 228, 787), (434, 407, 1001)]


def test_every_assumed_value_in_the_preset_names_a_source():
    for line in preset_text("paper").splitlines():
        if "[assumed]" in line:
            comment = line.split("[assumed]", 1)[1].strip()
            assert len(comment) > 10, line


def test_rigid_axis_differs_from_paper_only_where_marked(paper):
    # the compensation study variant: every changed value carries a [variant] comment
    text = preset_text("rigid_axis")
    marked = {line.split(":")[0].strip() for line in text.splitlines() if "[variant]" in line and not line.startswith("#")}
    assert marked == {"bearing_stiffness", "axial_stiffness", "velocity_gain", "velocity_integral_gain",
                      "preload_torque", "load_friction_coefficient", "nut_friction_on"}  # the former nut (issue 15)
    rigid = preset("rigid_axis")
    changed = {"screw.bearing_stiffness", "nut.axial_stiffness", "controller.velocity_gain",
               "controller.velocity_integral_gain", "nut.preload_torque", "nut.load_friction_coefficient",
               "friction.nut_friction_on"}
    for path in changed:
        assert get_value(rigid, path) != get_value(paper, path)
    for path in changed:
        rigid = with_value(rigid, path, get_value(paper, path))
    assert rigid == paper


def test_yaml_round_trip_is_identical(tmp_path, paper):
    path = tmp_path / "p.yaml"
    save_params(paper, path)
    assert load_params(path) == paper


def test_save_params_is_atomic(tmp_path, paper, monkeypatch):
    import drakecreep.files

    path = tmp_path / "p.yaml"
    path.write_text("old\n")

    def fail(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(drakecreep.files.os, "replace", fail)
    with pytest.raises(OSError):
        save_params(paper, path)
    assert path.read_text() == "old\n" and [p.name for p in tmp_path.iterdir()] == ["p.yaml"]


def test_exponent_without_sign_is_a_float(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text("nut: {axial_stiffness: 4.2e7}\n")
    assert load_params(path).nut.axial_stiffness == 4.2e7


@pytest.mark.parametrize("text, shown", [("1:30", "'1:30'"), ("050", "'050'"), ("0b11", "'0b11'"),
                                         ("1:30.5", "'1:30.5'")])
def test_base_60_octal_and_binary_numbers_are_text(tmp_path, text, shown):
    # YAML 1.1 read 'mass: 1:30' as 90 kg and 'mass: 050' as 40 kg, without a word
    path = tmp_path / "p.yaml"
    path.write_text(f"table: {{mass: {text}}}\n")
    with pytest.raises(InputError, match=f"^table.mass: got {shown}; allowed: a finite number"):
        load_params(path)


def test_a_signed_number_with_a_leading_point_is_a_float(tmp_path):
    # YAML 1.2 reads -.5 as -0.5; the hardened loader had left it text, so a valid negative asymmetry was refused
    path = tmp_path / "p.yaml"
    path.write_text("friction: {coulomb_asymmetry: -.05, viscous_asymmetry: +.02}\ntable: {seal_force: .5e1}\n")
    p = load_params(path)
    assert (p.friction.coulomb_asymmetry, p.friction.viscous_asymmetry, p.table.seal_force) == (-0.05, 0.02, 5.0)


def test_decimal_and_hex_integers_still_load(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text("table: {mass: 40}\nsensors: {encoder_counts_per_rev: 0x1000}\nnut: {mass: 0}\n")
    p = load_params(path)
    assert (p.table.mass, p.sensors.encoder_counts_per_rev, p.nut.mass) == (40.0, 4096, 0.0)


@pytest.mark.parametrize(
    "data, field, fragment",
    [
        ({"table": {"mass": -1.0}}, "table.mass", "[0.001, 100000.0] kg"),
        # 1e-30 kg: margins printed a damping ratio of 5e13 and negative margins, critical a creep verdict
        ({"table": {"mass": 1e-30}, "nut": {"mass": 0.0}}, "table.mass", "got 1e-30; allowed: a finite number in [0.001"),
        # 1e-15 s: simulate diverged after 1 ms, margins overflowed; 0 (ideal) and 1e-6 s load
        ({"motor": {"current_loop_time_constant": 1e-15}}, "motor.current_loop_time_constant",
         "got 1e-15; allowed: 0 (ideal) or a finite number in [1e-06, 0.1] s"),
        ({"simulation": {"accuracy": 1e-300}}, "simulation.accuracy",
         "got 1e-300; allowed: 0 (the friction law's default) or a finite number in [1e-12, 0.1]"),
        # 0.01 s with the 0.05 s ramp: simulate measured the acceleration and called it a creep verdict
        ({"simulation": {"steady_start": 0.01}}, "simulation.steady_start",
         "got 0.01; allowed: >= acceleration_time (0.05 s)"),
        # 1e9-1e20 N s/m: margins printed 'nan Hz' and, at 1e20, an open-loop unstable pole made by round-off
        ({"nut": {"axial_damping": 1e9}}, "nut.axial_damping", "got 1000000000.0; allowed: a finite number in [0.0, "
         "100000000.0] N s/m"),
        ({"screw": {"bearing_damping": 1e20}}, "screw.bearing_damping", "[0.0, 100000000.0] N s/m"),
        # -1e12 N: 3e9 N of guide friction, reported by simulate as sliding without creep at 28 % of the feed
        ({"loads": {"cases": [{"fz": -1e12}]}}, "loads.cases[0].fz", "[-1000000.0, 1000000.0] N"),
        ({"loads": {"cases": [{"fx": 1e19}]}}, "loads.cases[0].fx", "[-1000000.0, 1000000.0] N"),
        # one field, one description: -1 said 'a finite number >= 0 counts/rev', 1.5 'an integer'
        ({"sensors": {"encoder_counts_per_rev": -1}}, "sensors.encoder_counts_per_rev",
         "got -1; allowed: an integer >= 0 counts/rev"),
        ({"sensors": {"encoder_counts_per_rev": 1.5}}, "sensors.encoder_counts_per_rev",
         "got 1.5; allowed: an integer >= 0 counts/rev"),
        # fields that ran to nonsense (found by helper-31): a smooth run's ripple counted as stick-slip at a stick
        # threshold of the whole feed; friction that diverged at once or pushed the table backwards for minutes;
        # one encoder count per turn; a lead error whose slope ran the nut backwards
        ({"simulation": {"stick_threshold": 1.0}}, "simulation.stick_threshold", "(0.0, 0.5]"),
        ({"friction": {"viscous": 1e12}}, "friction.viscous", "[0.0, 100000000.0] N s/m"),
        ({"friction": {"bristle_damping": 1e8}}, "friction.bristle_damping", "[0.0, 1000000.0] N s/m"),
        ({"friction": {"bristle_stiffness": 1e20}}, "friction.bristle_stiffness", "[1.0, 100000000000.0] N/m"),
        ({"friction": {"bristle_stiffness": 1e-300}}, "friction.bristle_stiffness", "[1.0, 100000000000.0] N/m"),
        ({"sensors": {"encoder_counts_per_rev": 1}}, "sensors.encoder_counts_per_rev",
         "got 1; allowed: 0 (ideal) or an integer >= 100 counts/rev"),
        ({"disturbance": {"lead_error_amplitude": 1e-3}}, "disturbance.lead_error_amplitude",
         "a lead error whose slope 2 pi (a + 2 a2) / period stays below 1 (here 15.1"),
        ({"disturbance": {"lead_error_period": 1e-12}}, "disturbance.lead_error_period", "[1e-05, 0.1] m"),
        ({"disturbance": {"cogging_period": 1e-15}}, "disturbance.cogging_period", "[1e-05, 0.1] m"),
        ({"screw": {"lead": 0.0}}, "screw.lead", "[0.0001, 0.1] m"),
        # 2 pi peak_torque / lead overflowed: simulate reported creep of a still table, exit 0; margins blamed '--feed'
        ({"screw": {"lead": 1e-300}}, "screw.lead", "got 1e-300; allowed: a finite number in [0.0001, 0.1] m"),
        ({"screw": {"lead": 9.9e-5}}, "screw.lead", "[0.0001, 0.1] m"),
        ({"friction": {"viscous": float("nan")}}, "friction.viscous", "finite"),
        ({"motor": {"rotor_inertia": "big"}}, "motor.rotor_inertia", "finite number"),
        ({"table": {"mas": 3}}, "table.mas", "an unknown field"),
        ({"controller": {"sampled": "yes"}}, "controller.sampled", "true or false"),
        ({"friction": {"law": "maxwell"}}, "friction.law", "one of coulomb, stribeck, lugre, gms"),
        ({"loads": {"cases": [{"fx": 1.0}, {"fz": "x"}]}}, "loads.cases[1].fz", "finite"),
        ({"controller": {"position_period": 3e-4}}, "controller.position_period", "integer multiple"),
        ({"screw": {"root_diameter": 0.03}}, "screw.root_diameter", "nominal_diameter"),
        # the section pi d^2 / 4 underflowed to 0: 'internal error: ZeroDivisionError' in simulate, margins, report
        ({"screw": {"root_diameter": 1e-300}}, "screw.root_diameter", "a shaft whose axial stiffness E pi d^2 / 4 / "
                                                                      "length is at least 1 N/m"),
        ({"screw": {"youngs_modulus": 1e-300}}, "screw.youngs_modulus", "make it 6.22e-304 N/m"),
        # every element of the axial chain (1e-300 N/m: 'internal error: ZeroDivisionError' in simulate and margins)
        ({"screw": {"bearing_stiffness": 1e-300}}, "screw.bearing_stiffness", "a stiffness of at least 1 N/m"),
        ({"nut": {"axial_stiffness": 1e-300}}, "nut.axial_stiffness", "a stiffness of at least 1 N/m"),
        ({"nut": {"seat_joint_stiffness": 1e-300}}, "nut.seat_joint_stiffness", "0 (rigid, off) or a stiffness of"),
        ({"screw": {"seat_joint_stiffness": 0.5}}, "screw.seat_joint_stiffness", "0 (rigid, off) or a stiffness of"),
        # (v / vs)^2 overflowed: 'margins' ended in 'internal error: OverflowError: (34, 'Numerical result out of range')'
        ({"friction": {"stribeck_velocity": 1e-300}}, "friction.stribeck_velocity", "[1e-12, 1.0] m/s"),
        # the sampled loop's model rounds exp(p T) to 1: 'margins' printed a phase margin of -2.5 deg for 75.2 at 1e-20 s
        ({"controller": {"velocity_period": 1e-20, "position_period": 4e-20}}, "controller.velocity_period",
         "[1e-09, 0.1] s"),
        # gains of 1e20 ran as a loop chattering in saturation every sample: minutes per simulated second (leaf)
        ({"controller": {"velocity_gain": 1e20}}, "controller.velocity_gain", "(0.0, 1000000000.0] N s/m"),
        ({"controller": {"velocity_integral_gain": 1e13}}, "controller.velocity_integral_gain", "1000000000000.0] N/m"),
        ({"controller": {"position_gain": 2e4}}, "controller.position_gain", "[0.0, 10000.0] 1/s"),
    ],
)
def test_invalid_values_name_field_value_and_range(data, field, fragment):
    with pytest.raises(InputError) as info:
        params_from_dict(data)
    assert info.value.field == field
    assert fragment in str(info.value)
    assert "\n" not in str(info.value)


def test_the_lower_ends_themselves_and_the_zeros_that_mean_ideal_load():
    p = params_from_dict({"table": {"mass": 1e-3}, "motor": {"current_loop_time_constant": 1e-6},
                          "simulation": {"accuracy": 1e-12}})
    assert (p.table.mass, p.motor.current_loop_time_constant, p.simulation.accuracy) == (1e-3, 1e-6, 1e-12)
    p = params_from_dict({"motor": {"current_loop_time_constant": 0.0}, "simulation": {"accuracy": 0.0}})
    assert (p.motor.current_loop_time_constant, p.simulation.accuracy) == (0.0, 0.0)


def test_load_cases_are_capped_before_they_are_built():
    """100 000 load cases in a params file were read, built and checked for 49 s before a command said anything."""
    import time

    from drakecreep.params import MAX_LOAD_CASES, LoadCase, LoadParams

    start = time.perf_counter()
    with pytest.raises(InputError) as info:
        params_from_dict({"loads": {"cases": [{"fx": 1.0}] * 100_000}})
    assert time.perf_counter() - start < 1.0  # building the 100 000 cases alone took 4 s
    assert info.value.field == "loads.cases"
    assert str(info.value).startswith("loads.cases: got '100000 load cases'; allowed: at most 1000 load cases (")
    assert len(params_from_dict({"loads": {"cases": [{"fx": 1.0}] * MAX_LOAD_CASES}}).loads.cases) == MAX_LOAD_CASES
    with pytest.raises(InputError, match=r"^cases: got '1001 load cases'"):
        LoadParams(cases=(LoadCase(),) * (MAX_LOAD_CASES + 1))


@pytest.mark.parametrize("text, fragment", [
    ("2001-13-45", "(line 1, column 24): a value it cannot read (month must be in 1..12)"),
    ("!!float abc", "(line 1, column 24): a value it cannot read (could not convert string to float: 'abc')"),
    ("!!int 1.5", "a value it cannot read (invalid literal for int()"),
    ("1" + "0" * 5000, "(line 1, column 24): an integer of more than 4300 digits"),
])
def test_a_scalar_yaml_cannot_construct_is_bad_input(tmp_path, text, fragment):
    # the constructor's bare ValueError was 'internal error: ValueError: month must be in 1..12' (or 'Exceeds the
    # limit (4300 digits) for integer string conversion'), exit 1 (found by the fifth fuzzing pass)
    path = tmp_path / "p.yaml"
    path.write_text(f"motor: {{rotor_inertia: {text}}}\n")
    with pytest.raises(InputError) as info:
        load_params(path)
    assert info.value.field == str(path) and fragment in str(info.value) and "\n" not in str(info.value)


def test_invalid_yaml_is_one_clear_error(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text("table: [\n")
    with pytest.raises(InputError, match="invalid YAML"):
        load_params(path)


def test_with_value_and_get_value(paper):
    p = with_value(paper, "loads.cases[2].fx", 500.0)
    assert get_value(p, "loads.cases[2].fx") == 500.0
    assert get_value(paper, "loads.cases[2].fx") == 434.0
    with pytest.raises(InputError) as info:
        with_value(paper, "controller.velocity_period", 3e-4)
    assert info.value.field == "controller.position_period"
    with pytest.raises(InputError):
        with_value(paper, "screw.nope", 1.0)


def test_defaults_are_valid_and_integers_accepted_for_floats():
    p = params_from_dict({"table": {"mass": 50}})
    assert isinstance(p.table.mass, float) and p.table.mass == 50.0
    assert DriveParams() == params_from_dict({})
    assert math.isfinite(params_to_dict(preset())["motor"]["rotor_inertia"])


def test_a_measured_axis_model_is_refused_as_params_with_what_it_is(tmp_path):
    """The ``augmented_model.yaml`` of a P-P cascade diagnosis (``drakecreep.measured_axis``) is not a drive's
    params file: one error naming its kind and what reads it, not "kind: an unknown field"."""
    from drakecreep.gap.drake_diagnosis import DrakeDiagnosis

    model = tmp_path / "augmented_model.yaml"
    diag = DrakeDiagnosis(nominal=None, nominal_test_errors={}, ranking=(), claimed=(),
                          model={"parameters": {"mass": 90.0, "bristle_share": 0.7}, "flexible": False, "delay": 0.0},
                          test_errors={}, seconds=0.0, k_se=2.0)
    diag.save_model(model)
    with pytest.raises(InputError, match="drakecreep.measured_axis.*load_model") as err:
        load_params(model)
    assert "unknown field" not in str(err.value)


@pytest.mark.parametrize("build, field", [
    (lambda: DriveParams(motor="x"), "motor"),
    (lambda: DriveParams(motor=None), "motor"),
    (lambda: DriveParams(screw=DriveParams().motor), "screw"),
    (lambda: LoadParams(cases=(1, 2)), "cases"),
    (lambda: LoadParams(cases="abc"), "cases"),
    (lambda: LoadParams(cases=None), "cases"),
    (lambda: with_value(DriveParams(), "loads.cases", (1, 2)), "loads.cases"),
])
def test_groups_and_lists_of_the_api_are_typed(build, field):
    # they were accepted as given (DriveParams(motor="x") failed later, deep in the model, or not at all)
    with pytest.raises(InputError, match=f"^{field}: got .*; allowed: a (tuple of )?[A-Z]"):
        build()


def test_a_list_of_load_cases_is_kept_as_a_tuple():
    loads = LoadParams(cases=[LoadCase(fx=1.0)])
    assert loads.cases == (LoadCase(fx=1.0),) and hash(loads)


def test_numpy_scalars_are_numbers():
    # np.float32 and np.int64 were refused as 'a finite number' and 'an integer' (e.g. a value from np.arange)
    import numpy as np

    from drakecreep.params import MotorParams, SensorParams

    assert MotorParams(rotor_inertia=np.float32(1e-4)).rotor_inertia == pytest.approx(1e-4)
    counts = SensorParams(encoder_counts_per_rev=np.int64(4096)).encoder_counts_per_rev
    assert counts == 4096 and type(counts) is int
    paper = preset("paper")
    assert paper.load_case(np.int64(2)) == paper.load_case(2)


def test_true_is_no_load_case(paper):
    with pytest.raises(InputError, match="^load_case: got True"):
        paper.load_case(True)  # it was case 1


@pytest.mark.parametrize("path", [None, 1, {}, [], "", "   ", "a\0b"])
def test_load_params_names_a_path_that_is_no_path(path):
    """A script's load_params(None) ended in pathlib's TypeError, load_params('') said ': got '. (a directory)''."""
    from drakecreep.params import load_params

    with pytest.raises(InputError, match=r"^path: got .*; allowed: a file path"):
        load_params(path)


def test_two_mass_effects_name_the_first_field_of_each_effect_switched_on():
    """One list of the effects only the two-mass diagram has (the baseline and the multibody diagram refuse them by
    it): none on the paper rig, each effect once by its first field set, in a fixed order."""
    from drakecreep.params import two_mass_effects

    p = preset("paper")
    assert two_mass_effects(p) == []
    for path, value in (("friction.time_drift", -0.1), ("disturbance.cogging_2_force", 1.0),
                        ("friction.position_map_2", 0.1), ("friction.position_map_3", -0.2), ("nut.backlash", 8e-6)):
        p = with_value(p, path, value)
    assert two_mass_effects(p) == [("disturbance.cogging_2_force", 1.0, "the cogging"),
                                   ("friction.position_map_2", 0.1, "the friction map"),
                                   ("nut.backlash", 8e-6, "the nut's lost motion"),
                                   ("friction.time_drift", -0.1, "the friction drift")]
