import math

import numpy as np
import pytest
import yaml

from drakecreep.errors import InputError
from drakecreep.gap.measured import (
    EMPS_CONTROLLER,
    ControllerMeta,
    MeasuredData,
    MeasuredMeta,
    MeasuredRun,
    controller_gains,
    emps_data_dir,
    emps_path,
    load_emps,
    load_measured,
    save_measured,
)
from drakecreep.params import params_to_dict, preset

EMPS = emps_data_dir()

META = {"u_units": "V", "u_gain": 35.0,
        "controller": {"kind": "p_p_cascade", "kp": 100.0, "kv": 200.0, "saturation": 10.0,
                       "sample_time": 0.001, "position_filter": [0.5, 0.5]},
        "sensors": {"encoder_resolution": 5e-8}, "source": "synthetic"}


def _rows(n=20, dt=1e-3):
    t = np.arange(n) * dt
    return {"t": t, "x_ref": 1e-3 * t, "x_motor": 1e-3 * t - 1e-7, "u": np.sin(t), "f_ext": 0 * t + 2.0}


def _law(x_ref, x, controller=META["controller"]):
    """The P-P law's command of positions ``x`` (clipped): a synthetic run its declared controller could have made."""
    taps = controller["position_filter"]
    dx = np.diff(np.convolve(x, taps)[: x.size], prepend=x[0]) / controller["sample_time"]
    u = controller["kp"] * controller["kv"] * (x_ref - x) - controller["kv"] * dx
    return np.clip(u, -controller["saturation"], controller["saturation"])


def _write(tmp_path, cols=None, header=None, meta=META, name="run.csv"):
    cols = _rows() if cols is None else cols
    names = list(cols)
    csv_path = tmp_path / name
    lines = [",".join(header or names)]
    n = len(next(iter(cols.values())))
    for i in range(n):
        lines.append(",".join(repr(float(cols[c][i])) if isinstance(cols[c][i], (float, np.floating))
                              else str(cols[c][i]) for c in names))
    csv_path.write_text("\n".join(lines) + "\n")
    if meta is not None:
        (tmp_path / name.replace(".csv", ".yaml")).write_text(yaml.safe_dump(meta))
    return csv_path


def test_load_minimal_csv_with_units_in_header(tmp_path):
    cols = _rows()
    path = _write(tmp_path, cols, header=["t[s]", "x_ref [m]", "x_motor(m)", "u[V]", "f_ext[N]"])
    data = load_measured(path)
    run = data.run()
    assert run.label == "run" and run.n == 20
    assert run.dt == pytest.approx(1e-3)
    np.testing.assert_array_equal(run.u, cols["u"])
    np.testing.assert_allclose(run.force, 35.0 * cols["u"] + 2.0)
    assert data.meta.controller.kp == 100.0 and data.meta.sensors.encoder_resolution == 5e-8
    assert run.x_table is None


@pytest.mark.parametrize("drop", ["t", "x_ref", "x_motor", "u"])
def test_missing_column(tmp_path, drop):
    cols = _rows()
    del cols[drop]
    with pytest.raises(InputError, match=f"the columns {drop} as well"):
        load_measured(_write(tmp_path, cols))


def test_unknown_column(tmp_path):
    cols = _rows()
    cols["speed"] = cols["t"]
    with pytest.raises(InputError, match="speed"):
        load_measured(_write(tmp_path, cols))


def test_non_monotonic_time(tmp_path):
    cols = _rows()
    cols["t"][7], cols["t"][8] = cols["t"][8], cols["t"][7]
    with pytest.raises(InputError, match="strictly increasing") as err:
        load_measured(_write(tmp_path, cols))
    assert "t[8]" in str(err.value)


def test_repeated_time_is_non_monotonic(tmp_path):
    cols = _rows()
    cols["t"][5] = cols["t"][4]
    with pytest.raises(InputError, match="strictly increasing"):
        load_measured(_write(tmp_path, cols))


def test_non_uniform_time_and_tolerance(tmp_path):
    cols = _rows()
    cols["t"][10:] += 2e-6  # one step 0.2 % longer
    path = _write(tmp_path, cols)
    with pytest.raises(InputError, match="uniform sampling within a relative tolerance of 0.001"):
        load_measured(path)
    assert load_measured(path, dt_rtol=5e-3).run().n == 20  # within a looser, explicit tolerance


def test_nan(tmp_path):
    cols = _rows()
    cols["x_motor"][3] = float("nan")
    with pytest.raises(InputError, match="NaN at data row 4") as err:
        load_measured(_write(tmp_path, cols))
    assert "x_motor" in err.value.field


def test_inf_is_named_by_its_data_row(tmp_path):
    """An inf cell is named as a NaN is, by the data row a user finds in the file (it was the sample index)."""
    cols = _rows()
    cols["u"][5] = -float("inf")
    with pytest.raises(InputError, match=r"-inf at data row 6 \(1 NaN, inf or empty\)") as err:
        load_measured(_write(tmp_path, cols))
    assert err.value.field.endswith("column u")


def test_positions_in_the_wrong_unit_are_refused_by_their_speed(tmp_path):
    n, dt = 400, 1e-3
    t = np.arange(n) * dt
    x = 0.05 * np.sin(2 * np.pi * t)  # 0.31 m/s peak: a feed axis
    x_motor = x - 1e-6 * np.cos(2 * np.pi * t)
    cols = {"t": t, "x_ref": x, "x_motor": x_motor, "u": _law(x, x_motor)}
    assert load_measured(_write(tmp_path, cols)).run().n == n
    # the same run in millimetres, labelled m: 314 m/s
    with pytest.raises(InputError, match="m/s") as err:
        load_measured(_write(tmp_path, {**cols, "x_ref": 1e3 * x, "x_motor": 1e3 * x}, name="mm.csv"))
    assert err.value.field.endswith("mm.csv: x_ref (run mm)") and "unit" in err.value.allowed
    # one encoder glitch (a single sample of 50 m/s) is not a unit error
    glitch = cols["x_motor"].copy()
    glitch[200] += 0.05
    assert load_measured(_write(tmp_path, {**cols, "x_motor": glitch}, name="glitch.csv")).run().n == n
    # ... but 2 % of such samples is
    fast = cols["x_motor"].copy()
    fast[::50] += 0.05
    with pytest.raises(InputError, match="x_motor"):
        load_measured(_write(tmp_path, {**cols, "x_motor": fast}, name="fast.csv"))


def test_a_resolution_the_recorded_positions_contradict_is_refused(tmp_path):
    """A counting sensor moves by whole counts: a count given in the wrong unit shows as shorter steps."""
    n, dt, count = 2000, 1e-3, 5e-8
    t = np.arange(n) * dt
    x = 0.01 * (1 - np.cos(np.pi * t))  # 0 .. 31 mm/s, slow at both ends
    counted = np.round(x / count) * count
    cols = {"t": t, "x_ref": x, "x_motor": counted, "x_table": counted, "u": np.sin(t)}
    meta = {**META, "sensors": {"encoder_resolution": count, "scale_resolution": count}}
    assert load_measured(_write(tmp_path, cols, meta=meta)).run().n == n
    for field in ("encoder_resolution", "scale_resolution"):  # 50 um: the count in mm written as m
        wrong = {**META, "sensors": {**meta["sensors"], field: 1e3 * count}}
        with pytest.raises(InputError) as err:
            load_measured(_write(tmp_path, cols, meta=wrong, name=f"{field}.csv"))
        assert err.value.field.endswith(f"sensors.{field} (run {field})") and err.value.value == 1e3 * count
        assert ("x_motor" if field == "encoder_resolution" else "x_table") in err.value.allowed
    # an unquantized (simulated) position is not checked against a count of 0
    ideal = {**META, "sensors": {"encoder_resolution": 0.0}}
    assert load_measured(_write(tmp_path, {**cols, "x_motor": x}, meta=ideal, name="ideal.csv")).run().n == n


def test_a_drive_command_that_is_zero_throughout_is_refused(tmp_path):
    cols = _rows()
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, {**cols, "u": 0 * cols["t"]}))
    assert err.value.field.endswith("u (run run)") and err.value.value == "zero throughout"


def test_a_drive_force_below_a_micronewton_is_refused(tmp_path):
    """A u of 1e-300 (varying) ran to 'y: got all zero', an internal name, from the nominal's fit (found by fuzzing)."""
    cols = _rows()
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, {**cols, "u": 1e-300 * (1.0 + np.sin(cols["t"]))}))
    assert err.value.field.endswith("u (run run)") and err.value.value.startswith("a peak drive force u x u_gain of ")


def test_a_drive_command_of_one_value_throughout_is_refused(tmp_path):
    """A u of 1.0 in every row (found by fuzzing) diagnosed to NaN errors with exit 0."""
    cols = _rows()
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, {**cols, "u": 0 * cols["t"] + 1.0}))
    assert err.value.field.endswith("u (run run)") and err.value.value.startswith("constant at 1 ")


def test_not_a_number(tmp_path):
    cols = {k: list(v) for k, v in _rows().items()}
    cols["u"][2] = "abc"
    with pytest.raises(InputError, match="abc"):
        load_measured(_write(tmp_path, cols))
    # float() reads Python's digit grouping: '1_5' was read as 15, silently
    cols["u"][2] = "1_5"
    with pytest.raises(InputError, match="got '1_5'; allowed: numbers"):
        load_measured(_write(tmp_path, cols, name="grouped.csv"))


def test_unknown_unit_of_u(tmp_path):
    with pytest.raises(InputError, match="one of N, A, V") as err:
        load_measured(_write(tmp_path, meta={**META, "u_units": "mV"}))
    assert err.value.field == f"{tmp_path / 'run.yaml'}: u_units"


def test_an_unknown_metadata_key_is_named_with_the_known_ones(tmp_path):
    """A misspelt top-level key of the metadata YAML gets the same one line as an unknown params field: the key,
    and the known keys."""
    with pytest.raises(InputError, match="an unknown field") as err:
        load_measured(_write(tmp_path, meta={**META, "u_gian": 35.0}))
    assert err.value.field.endswith(": u_gian") and "u_gain" in str(err.value) and "u_units" in str(err.value)


def test_unit_of_u_in_header_must_match_metadata(tmp_path):
    path = _write(tmp_path, header=["t", "x_ref", "x_motor", "u[A]", "f_ext"])
    with pytest.raises(InputError, match="u is in the metadata's u_units") as err:
        load_measured(path)
    assert "column u unit" in err.value.field and err.value.value == "A"


def test_units_in_the_header_are_converted_to_si(tmp_path):
    si = _rows()
    shop = {"t": si["t"] * 1e3, "x_ref": si["x_ref"] * 1e3, "x_motor": si["x_motor"] * 1e6, "u": si["u"] * 1e3,
            "f_ext": si["f_ext"] * 1e-3}
    (tmp_path / "si").mkdir()
    (tmp_path / "shop").mkdir()
    a = load_measured(_write(tmp_path / "si", si)).runs[0]
    b = load_measured(_write(tmp_path / "shop", shop, header=["t[ms]", "x_ref[mm]", "x_motor [um]", "u(mV)",
                                                               "f_ext[kN]"])).runs[0]
    for name in ("t", "x_ref", "x_motor", "u", "f_ext"):
        np.testing.assert_allclose(getattr(b, name), getattr(a, name), rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("header, field", [
    (["t[h]", "x_ref", "x_motor", "u", "f_ext"], "column t unit"),
    (["t", "x_ref", "x_motor[inch]", "u", "f_ext"], "column x_motor unit"),
    (["t", "x_ref", "x_motor", "u", "f_ext[lbf]"], "column f_ext unit"),
])
def test_unknown_unit_names_the_column_and_the_allowed_units(tmp_path, header, field):
    with pytest.raises(InputError, match="one of") as err:
        load_measured(_write(tmp_path, header=header))
    assert field in err.value.field


@pytest.mark.parametrize("suffix", [".parquet", ".mat"])
def test_other_formats_with_a_column_mapping(tmp_path, suffix):
    import pandas as pd
    import scipy.io

    si = _rows()
    reference = load_measured(_write(tmp_path, si)).runs[0]
    theirs = {"time_ms": si["t"] * 1e3, "cmd": si["x_ref"], "enc_mm": si["x_motor"] * 1e3, "volts": si["u"],
              "load": si["f_ext"]}
    path = tmp_path / f"rig{suffix}"
    if suffix == ".parquet":
        pd.DataFrame(theirs).to_parquet(path)
    else:
        scipy.io.savemat(path, {k: v.reshape(-1, 1) for k, v in theirs.items()})
    meta = {**META, "file": {"columns": {"t": "time_ms", "x_ref": "cmd", "x_motor": "enc_mm", "u": "volts",
                                         "f_ext": "load"},
                             "units": {"t": "ms", "x_motor": "mm"}}}
    (tmp_path / "rig.yaml").write_text(yaml.safe_dump(meta))
    run = load_measured(path, tmp_path / "rig.yaml").runs[0]
    for name in ("t", "x_ref", "x_motor", "u", "f_ext"):
        np.testing.assert_allclose(getattr(run, name), getattr(reference, name), rtol=1e-12, atol=1e-15)


def test_a_mapping_that_leaves_signals_out_names_file_columns(tmp_path):
    # the header names every signal, but a mapping replaces the header's names: the missing ones are named there
    meta = {**META, "file": {"columns": {"x_ref": "x_motor"}}}
    with pytest.raises(InputError, match=r"run.yaml: file.columns: got 'x_ref'; allowed: a mapping that names the "
                                         r"columns of t, x_motor, u as well \(with file.columns every signal"):
        load_measured(_write(tmp_path, meta=meta))


def test_a_mapping_to_a_missing_column_names_it(tmp_path):
    path = _write(tmp_path)
    meta = {**META, "file": {"columns": {"t": "time"}}}
    (tmp_path / "m.yaml").write_text(yaml.safe_dump(meta))
    with pytest.raises(InputError, match="a column of the file") as err:
        load_measured(path, tmp_path / "m.yaml")
    assert err.value.field.endswith("file.columns.t")


def test_gain_must_be_one_for_force(tmp_path):
    with pytest.raises(InputError, match="1 when u_units is N"):
        load_measured(_write(tmp_path, meta={**META, "u_units": "N", "u_gain": 35.0}))


def test_gain_required_for_volts(tmp_path):
    meta = {k: v for k, v in META.items() if k != "u_gain"}
    with pytest.raises(InputError, match="N per V"):
        load_measured(_write(tmp_path, meta=meta))


def test_current_gain_derived_from_params(tmp_path):
    p = preset("paper")
    meta = {"u_units": "A", "params": params_to_dict(p)}
    data = load_measured(_write(tmp_path, meta=meta))
    assert data.meta.u_gain == pytest.approx(p.motor.torque_constant * 2 * math.pi / p.screw.lead)
    assert data.meta.params == p


def test_params_file_relative_to_metadata(tmp_path):
    from drakecreep.params import save_params, with_value

    p = with_value(preset("paper"), "screw.lead", 4e-3)
    save_params(p, tmp_path / "rig.yaml")
    data = load_measured(_write(tmp_path, meta={**DRAKECREEP_META, "params": "rig.yaml"}))
    assert data.meta.params.screw.lead == 4e-3


#: a run of the project's own cascade: its controller is the params file's
DRAKECREEP_META = {"u_units": "N", "u_gain": 1.0, "controller": {"kind": "drakecreep"}, "source": "synthetic"}


@pytest.mark.parametrize("meta, field, allowed", [
    # a params file beside the P-P law: never read (only u_units A without u_gain takes its torque constant)
    ({**META, "params": "rig.yaml"}, "run.yaml: params", "only with controller kind drakecreep"),
    ({k: v for k, v in META.items() if k != "controller"} | {"params": "rig.yaml"}, "run.yaml: params",
     "only with controller kind drakecreep"),
    # kind drakecreep replays the params file's controller: a feedback or sample time that contradicts it was ignored
    ({**DRAKECREEP_META, "params": "rig.yaml", "controller": {"kind": "drakecreep", "feedback": "table"}},
     "run.yaml: controller.feedback", "the params file's controller.position_feedback (motor), or left out"),
    ({**DRAKECREEP_META, "params": "rig.yaml", "controller": {"kind": "drakecreep", "sample_time": 0.005}},
     "run.yaml: controller.sample_time", "the params file's controller.position_period (0.001 s), or left out"),
])
def test_metadata_a_diagnosis_would_ignore_is_refused(tmp_path, meta, field, allowed):
    from drakecreep.params import save_params

    save_params(preset("paper"), tmp_path / "rig.yaml")
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, meta=meta))
    assert err.value.field.endswith(field) and err.value.allowed.startswith(allowed)
    # what agrees with the params file, or is left out, loads
    agreeing = {**DRAKECREEP_META, "params": "rig.yaml",
                "controller": {"kind": "drakecreep", "feedback": "motor", "sample_time": 0.001}}
    assert load_measured(_write(tmp_path, meta=agreeing)).meta.controller.kind == "drakecreep"


def test_an_empty_params_mapping_or_file_is_refused_not_read_as_the_default_rig(tmp_path):
    with pytest.raises(InputError, match=r"run.yaml: params: got 'an empty mapping \(\{\}\)'"):
        load_measured(_write(tmp_path, meta={**META, "params": {}}))
    (tmp_path / "rig.yaml").write_text("{}\n")
    with pytest.raises(InputError, match=r"rig.yaml: got 'an empty mapping \(\{\}\)'; allowed: a YAML mapping of "
                                         "parameter groups"):
        load_measured(_write(tmp_path, meta={**META, "params": "rig.yaml"}))


def test_the_metadata_named_as_its_own_params_file_is_said_to_be_metadata(tmp_path):
    with pytest.raises(InputError, match="run.yaml: got \"a measured run's metadata file \\(it has u_units\\)\"; "
                                         "allowed: a drakecreep params file"):
        load_measured(_write(tmp_path, meta={**META, "params": "run.yaml"}))


def test_row_length_mismatch(tmp_path):
    path = _write(tmp_path)
    lines = path.read_text().splitlines()
    lines[5] = lines[5] + ",1.0"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match="line 6, saw 6"):
        load_measured(path)


@pytest.mark.parametrize("on_header", [True, False])
def test_a_trailing_comma_on_every_line_is_an_empty_field_not_a_shift_of_the_columns(tmp_path, on_header):
    cols = _rows()
    path = _write(tmp_path, cols)
    lines = path.read_text().splitlines()
    header = lines[0] + ("," if on_header else "")
    path.write_text("\n".join([header] + [line + "," for line in lines[1:]]) + "\n")
    run = load_measured(path).run()
    np.testing.assert_array_equal(run.t, cols["t"])
    np.testing.assert_array_equal(run.u, cols["u"])


def test_every_row_longer_than_the_header_is_refused_not_shifted(tmp_path):
    path = _write(tmp_path)
    lines = path.read_text().splitlines()
    path.write_text("\n".join(lines[:1] + [line + ",5.0" for line in lines[1:]]) + "\n")
    with pytest.raises(InputError, match="more values than the header has column names"):
        load_measured(path)


def test_a_repeated_column_is_named(tmp_path):
    cols = _rows()
    path = _write(tmp_path, cols, header=["t[s]", "x_ref[m]", "x_ref[m]", "u[V]", "f_ext[N]"])
    with pytest.raises(InputError, match="header: got 'x_ref'; allowed: each column once"):
        load_measured(path)


@pytest.mark.parametrize("separator, decimal", [(";", ","), (";", "."), ("\t", "."), ("\t", ",")])
def test_semicolon_and_tab_separated_files_with_either_decimal_mark(tmp_path, separator, decimal):
    """Spreadsheet and scope exports in many locales: ``;`` or tab between fields, often a decimal comma. The
    header line gives the separator, the first data row the decimal mark."""
    cols = _rows()
    path = _write(tmp_path, cols)
    lines = path.read_text().splitlines()
    path.write_text("# exported by a scope\n" + "\n".join(
        line.replace(",", separator).replace(".", decimal) for line in lines) + "\n")
    run = load_measured(path).run()
    np.testing.assert_allclose(run.t, cols["t"], rtol=0, atol=1e-15)
    np.testing.assert_allclose(run.u, cols["u"], rtol=1e-15)


def test_the_metadata_may_name_the_separator_and_the_decimal_mark(tmp_path):
    cols = _rows()
    meta = dict(META, file={"separator": ";", "decimal": ","})
    path = _write(tmp_path, cols, meta=meta)
    lines = path.read_text().splitlines()
    path.write_text("\n".join(line.replace(",", ";").replace(".", ",") for line in lines) + "\n")
    np.testing.assert_allclose(load_measured(path).run().u, cols["u"], rtol=1e-15)


@pytest.mark.parametrize("file, field", [({"separator": "|"}, "file.separator"), ({"decimal": ";"}, "file.decimal"),
                                         ({"separator": [";"]}, "file.separator"),
                                         ({"separator": ",", "decimal": ","}, "file.decimal"),
                                         # a decimal comma on a file whose header separates by commas (was ignored)
                                         ({"decimal": ","}, "file.decimal: got ','; allowed: a mark other than the "
                                                            "file's separator ','"),
                                         ({"units": {"run": "s"}}, "file.units.run: got 's'; allowed: no unit")])
def test_a_bad_separator_or_decimal_mark_is_named(tmp_path, file, field):
    with pytest.raises(InputError, match=field):
        load_measured(_write(tmp_path, meta=dict(META, file=file)))


def test_a_run_whose_rows_are_in_two_blocks_is_refused_with_where(tmp_path):
    cols = _rows(30)
    cols["run"] = ["A"] * 10 + ["B"] * 10 + ["A"] * 10
    with pytest.raises(InputError, match="A: data rows 1-10 and again from 21.*each run's rows together"):
        load_measured(_write(tmp_path, cols))


def test_array_length_mismatch_in_constructor():
    r = _rows()
    meta = MeasuredMeta(u_units="N", u_gain=1.0)
    with pytest.raises(InputError, match="length 20, the length of t") as err:
        MeasuredRun(t=r["t"], x_ref=r["x_ref"], x_motor=r["x_motor"][:-1], u=r["u"], meta=meta)
    assert err.value.field == "x_motor"


def test_missing_metadata(tmp_path):
    with pytest.raises(InputError, match="metadata YAML beside the CSV"):
        load_measured(_write(tmp_path, meta=None))


def test_bad_controller_metadata(tmp_path):
    bad = {**META, "controller": {**META["controller"], "position_filter": [0.5, 0.4]}}
    with pytest.raises(InputError, match="summing to 1"):
        load_measured(_write(tmp_path, meta=bad))
    bad = {**META, "controller": {**META["controller"], "kind": "pid"}}
    with pytest.raises(InputError, match="p_p_cascade, drakecreep"):
        load_measured(_write(tmp_path, meta=bad))
    for gain in ("kp", "kv"):
        # A P-P cascade whose gain is left out would be replayed as an open loop: refused, naming the gain.
        bad = {**META, "controller": {k: v for k, v in META["controller"].items() if k != gain}}
        with pytest.raises(InputError, match=f"controller.{gain}: got 'nothing .the key is missing.'; allowed: a "
                                             "number > 0"):
            load_measured(_write(tmp_path, meta=bad))
        bad = {**META, "controller": {**META["controller"], gain: 0}}
        with pytest.raises(InputError, match=f"controller.{gain}: got 0.0; allowed: a number > 0"):
            load_measured(_write(tmp_path, meta=bad))


def test_the_p_p_laws_fields_are_refused_for_the_projects_cascade_unless_at_their_defaults(tmp_path):
    own = {"kind": "drakecreep", "sample_time": 0.001}
    for name, value in (("kp", 5.0), ("kv", 200.0), ("saturation", 10.0), ("position_filter", [0.5, 0.5])):
        with pytest.raises(InputError, match=f"controller.{name}: got .*; allowed: nothing for kind drakecreep: its "
                                             "gains and periods are the params file's controller group"):
            ControllerMeta.from_dict({**own, name: value})
    # the defaults (an older to_dict wrote them) are read; to_dict leaves the P-P law's fields out
    old = ControllerMeta.from_dict({**own, "kp": 0.0, "kv": 0.0, "saturation": ".inf", "position_filter": [1.0]})
    assert old == ControllerMeta.from_dict(own)
    assert set(old.to_dict()) == {"kind", "sample_time", "feedback"}
    assert ControllerMeta.from_dict(old.to_dict()) == old
    with pytest.raises(InputError, match="controller.kp: got -160.18; allowed: a number > 0 .the P-P cascade's gain"):
        ControllerMeta.from_dict({**META["controller"], "kp": -160.18})  # said '>= 0.0', while 0 needs '> 0'


def test_a_time_column_in_another_unit_is_named_by_the_sample_time_not_by_a_gain(tmp_path):
    rows = _rows(n=200)
    rows["u"] = _law(rows["x_ref"], rows["x_motor"])
    rows["t"] = np.arange(200) * 1.0  # milliseconds under a header that says seconds
    with pytest.raises(InputError, match=r"controller.sample_time \(run run\): got 0.001; allowed: the run's sample "
                                         r"time 1 s, or a whole fraction or multiple of it within a factor of 10 \(is the "
                                         r"unit of t wrong\?\)"):
        load_measured(_write(tmp_path, cols=rows))


def test_several_runs_and_round_trip(tmp_path):
    a, b = _rows(12), _rows(15, dt=2e-3)
    b["t"] = b["t"] + 5.0
    cols = {k: list(a[k]) + list(b[k]) for k in a}
    cols["x_table"] = cols["x_motor"]
    cols["run"] = ["up"] * 12 + ["down"] * 15
    data = load_measured(_write(tmp_path, cols))
    assert data.labels == ("up", "down")
    assert data.run("down").n == 15 and data.run("down").dt == pytest.approx(2e-3)
    with pytest.raises(InputError, match="one of up, down"):
        data.run("left")
    with pytest.raises(InputError, match="a label"):
        data.run()

    out_csv, out_meta = save_measured(data, tmp_path / "copy.csv")
    back = load_measured(out_csv)
    assert out_meta == tmp_path / "copy.yaml"
    assert back.meta == data.meta
    for r0, r1 in zip(data, back):
        assert r0.label == r1.label
        for name in ("t", "x_ref", "x_motor", "x_table", "u", "f_ext"):
            np.testing.assert_array_equal(getattr(r0, name), getattr(r1, name))


def test_round_trip_with_params_and_single_run(tmp_path):
    p = preset("paper")
    r = _rows()
    meta = MeasuredMeta(u_units="A", u_gain=500.0, params=p, controller=ControllerMeta(kind="drakecreep"),
                        notes="unit test")
    run = MeasuredRun(t=r["t"], x_ref=r["x_ref"], x_motor=r["x_motor"], u=r["u"], meta=meta, label="single")
    save_measured(run, tmp_path / "single.csv")
    back = load_measured(tmp_path / "single.csv").run()
    assert back.meta == meta and back.label == "single" and back.f_ext is None
    np.testing.assert_array_equal(back.x_motor, run.x_motor)


def test_time_jitter_of_emps_size_is_accepted():
    r = _rows(200)
    rng = np.random.default_rng(0)
    t = r["t"] + rng.normal(0, 2e-8, r["t"].size)  # EMPS: std 2e-8 s on 1 ms
    run = MeasuredRun(t=t, x_ref=r["x_ref"][:200], x_motor=r["x_motor"], u=r["u"],
                      meta=MeasuredMeta(u_units="N", u_gain=1.0))
    assert run.dt == pytest.approx(1e-3, rel=1e-4)


def test_emps_files_ship_with_the_package():
    assert emps_path("validation") == emps_data_dir() / "DATA_EMPS_PULSES.mat"
    assert emps_path("estimation").stat().st_size > 500_000
    with pytest.raises(InputError, match="estimation, validation"):
        emps_path("test")


def test_emps_estimation_loader():
    data = load_emps(emps_path("estimation"))
    run = data.run()
    assert isinstance(data, MeasuredData) and run.label == "DATA_EMPS"
    assert run.n == 24841 and run.dt == pytest.approx(1e-3, rel=1e-6)
    assert run.t[0] == 0 and run.t[-1] == pytest.approx(24.84)
    assert run.meta.u_units == "V" and run.u_gain == pytest.approx(35.15065188)
    assert run.meta.controller == EMPS_CONTROLLER
    assert run.f_ext is None and run.x_table is None
    assert run.x_ref[0] == pytest.approx(1.0782e-4, rel=1e-3)
    assert 0.24 < run.x_motor.max() < 0.25  # m: the stroke is about a quarter metre
    np.testing.assert_allclose(run.force[:2], 35.15065188 * np.array([2.53862809, 2.62483504]), rtol=1e-8)
    # every qm is a whole number of 50 nm encoder counts
    counts = run.x_motor / run.meta.sensors.encoder_resolution
    assert np.max(np.abs(counts - np.round(counts))) < 1e-6


@pytest.mark.parametrize("name", ["vir", "qm", "gtau"])
def test_an_emps_file_of_complex_signals_is_refused_by_name(tmp_path, name):
    """A complex vir was read as its real part with a ComplexWarning and diagnosed (the measured files refuse it)."""
    import scipy.io

    t = np.arange(3000) * 1e-3
    mat = dict(t=t, qm=0.1 * np.sin(2 * np.pi * t), qg=0.1 * np.sin(2 * np.pi * t), vir=np.cos(t), gtau=35.15,
               kp=160.18, kv=243.45)
    mat[name] = mat[name] + 1j
    scipy.io.savemat(tmp_path / "DATA_EMPS.mat", mat)
    with pytest.raises(InputError) as err:
        load_emps(tmp_path / "DATA_EMPS.mat")
    assert err.value.field.endswith(f"DATA_EMPS.mat: {name}") and err.value.value == "complex numbers (complex128)"
    assert err.value.allowed == "real numbers"


@pytest.mark.parametrize("name, change, said", [
    # both named the run's column, a name the file does not have ('x_motor: got ...'); zeros reached the fit as
    # 'y: got 'all zero'' (the force it fits), after the load
    ("qm", lambda a: np.where(np.arange(a.size).reshape(a.shape) == 100, np.nan, a), "nan at sample 100"),
    ("vir", np.zeros_like, "zero throughout"),
    ("t", lambda a: a[::-1].copy(), "after t[0]"),
    # the metadata's fields too ('u_gain: got -35.15', 'controller.kp: got 1e+300' named no file)
    ("gtau", lambda a: -a, "-35.15"),
    ("kp", lambda a: a * 0 + 1e300, "1e+300"),
])
def test_a_bad_emps_variable_is_named_as_the_file_names_it(tmp_path, name, change, said):
    import scipy.io

    mat = {k: v for k, v in scipy.io.loadmat(str(emps_path("estimation"))).items() if not k.startswith("__")}
    mat[name] = change(mat[name])
    scipy.io.savemat(tmp_path / "DATA_EMPS.mat", mat)
    with pytest.raises(InputError) as err:
        load_emps(tmp_path / "DATA_EMPS.mat")
    assert err.value.field == f"{tmp_path / 'DATA_EMPS.mat'}: {name}" and said in str(err.value.value)


def test_emps_controller_law_reproduces_the_recorded_output():
    """The documented law, fed the recorded qm and qg, gives the recorded u (after removing the pulses)."""
    for which, worst in (("estimation", 0.01), ("validation", 0.1)):
        run = load_emps(which).run()
        c = run.meta.controller
        q = run.x_motor
        qf = 0.5 * q + 0.5 * np.r_[q[0], q[:-1]]
        dq = np.r_[0.0, np.diff(qf)] / c.sample_time
        u = np.clip(c.kp * c.kv * (run.x_ref - q) - c.kv * dq, -c.saturation, c.saturation)
        rms = np.sqrt(np.mean((run.u - u)[10:] ** 2))
        assert rms < worst, which  # V; the recorded u is 1.5 V rms


def test_emps_validation_pulses_are_drive_volts():
    run = load_emps("validation").run()
    pulses = run.f_ext / run.u_gain
    assert set(np.unique(pulses)) == {0.0, 5.0}
    np.testing.assert_allclose(run.force, run.u_gain * (run.u + pulses), rtol=1e-12, atol=1e-9)
    edges = np.flatnonzero(np.diff(pulses))
    recorded = run.u + pulses  # the file's vir
    jumps = recorded[edges + 1] - recorded[edges]
    np.testing.assert_allclose(np.abs(jumps), 5.0, atol=0.6)  # vir jumps by the pulse at every edge


@pytest.mark.parametrize("gain", [1e300, 1e-300, 1e10])
def test_absurd_u_gain_is_refused_where_it_is_read(tmp_path, gain):
    # 1e300 passed the file check and overflowed the identification ("axis.damping: got inf")
    with pytest.raises(InputError, match=r"u_gain: got .*allowed: a gain in \[1e-09, 1e\+09\] N per V"):
        load_measured(_write(tmp_path, meta={**META, "u_gain": gain}))


def test_time_errors_show_plain_numbers(tmp_path):
    cols = _rows()
    cols["t"] = [float(x) for x in cols["t"]]
    cols["t"][5] = cols["t"][4]
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, cols=cols))
    assert "np.float64" not in str(err.value) and "strictly increasing" in str(err.value)


def test_save_measured_keeps_the_old_file_when_writing_fails(tmp_path, monkeypatch):
    from drakecreep.data import example_path
    from drakecreep.gap import measured

    data = measured.load_measured(example_path("emps_segment.csv"))
    csv_path, _ = measured.save_measured(data, tmp_path / "runs.csv")
    before = csv_path.read_text()
    calls = {"n": 0}
    real = np.column_stack

    def failing(arrays):
        calls["n"] += 1
        raise OSError("disk full")

    monkeypatch.setattr(measured.np, "column_stack", failing)
    with pytest.raises(OSError):
        measured.save_measured(data, csv_path)
    monkeypatch.setattr(measured.np, "column_stack", real)
    assert calls["n"] == 1 and csv_path.read_text() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["runs.csv", "runs.yaml"]  # no temporary left


def test_run_labels_are_read_as_written(tmp_path):
    """A numeric run column was read as numbers: labels 1 and 1.0 were one run (two runs merged without a word when
    the time ran on), 007 became '7.0'."""
    lines = ["t[s],x_ref[m],x_motor[m],u[N],run"]
    for k, label in enumerate(("1", "1.0", "007")):
        for i in range(30):
            n = 30 * k + i
            lines.append(f"{n * 1e-3},{n * 1e-5},{n * 1e-5},{1.5 + 0.1 * (i % 2)},{label}")
    (tmp_path / "runs.csv").write_text("\n".join(lines) + "\n")
    (tmp_path / "runs.yaml").write_text("u_units: N\nu_gain: 1.0\n")
    data = load_measured(tmp_path / "runs.csv")
    assert data.labels == ("1", "1.0", "007")
    assert [r.n for r in data.runs] == [30, 30, 30]


@pytest.mark.parametrize("change, field", [
    ({"params": {"screw": {"lead": -1.0}}}, "run.yaml: params.screw.lead"),
    ({"params": "rig.yaml"}, "rig.yaml: screw.lead"),  # the params file the metadata names
    ({"controller": dict(META["controller"], sample_time=-1.0)}, "run.yaml: controller.sample_time"),
    ({"sensors": {"encoder_resolution": -1.0}}, "run.yaml: sensors.encoder_resolution"),
])
def test_a_bad_field_of_the_metadata_names_its_file(tmp_path, change, field):
    """A diagnosis reads runs, metadata, a params file and perhaps a scored file: 'screw.lead: got -1.0' alone did
    not say which file holds it."""
    (tmp_path / "rig.yaml").write_text("screw: {lead: -1.0}\n")
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, meta=dict(META, **change)))
    assert str(err.value.field).endswith(field) and err.value.value == -1.0


@pytest.mark.parametrize("change, field, allowed", [
    ({"u_gain": 10 ** 400}, "run.yaml: u_gain", "a finite number"),
    ({"controller": dict(META["controller"], kp=10 ** 400)}, "run.yaml: controller.kp", "a finite number"),
    ({"controller": dict(META["controller"], saturation=10 ** 400)}, "run.yaml: controller.saturation", "a number > 0"),
    ({"sensors": {"encoder_resolution": 10 ** 400}}, "run.yaml: sensors.encoder_resolution", "a finite number"),
])
def test_an_integer_of_hundreds_of_digits_in_the_metadata_is_named(tmp_path, change, field, allowed):
    """'u_gain: 999...9' (400 digits) ended in 'internal error: OverflowError: int too large to convert to float'."""
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, meta=dict(META, **change)))
    assert err.value.field == str(tmp_path / field) and err.value.allowed.startswith(allowed)


@pytest.mark.parametrize("change, field", [({"u_gain": -35.0}, "u_gain"), ({"u_units": "W"}, "u_units")])
def test_a_bad_unit_or_gain_of_u_names_the_metadata_file(tmp_path, change, field):
    """The other fields of the metadata named their file since dda36be; u_gain and u_units did not."""
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, meta=dict(META, **change)))
    assert err.value.field == str(tmp_path / f"run.yaml: {field}")


@pytest.mark.parametrize("taps, value", [
    ("10", "10"),  # a quoted '10' was the taps 1, 0 (its characters)
    (True, True),  # true was the tap 1
    ([0.5, "0.5"], [0.5, "0.5"]),
    ([1e300, -1e300, 1.0], "3 taps, sum of |taps| 2e+300"),  # summed to 1, replayed without end
    ([1e-4] * 10000, "10000 taps, sum of |taps| 1"),  # each tap a state of the replay: never finished
])
def test_a_position_filter_that_is_text_or_cannot_be_replayed_is_refused(tmp_path, taps, value):
    meta = dict(META, controller=dict(META["controller"], position_filter=taps))
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, meta=meta))
    assert err.value.field.endswith("run.yaml: controller.position_filter") and err.value.value == value


def test_a_position_filter_of_few_taps_of_any_sign_is_kept():
    for taps in ((0.5, 0.5), (2.0, -1.0), (4.0, -6.0, 4.0, -1.0), (1 / 256,) * 256):
        assert ControllerMeta(kp=1.0, kv=1.0, position_filter=taps).position_filter == pytest.approx(taps)


def test_a_recorded_u_beyond_the_declared_saturation_is_refused(tmp_path):
    """A P-P cascade clips its output at its saturation: 'saturation: 1e-300' with u up to 4.3 V replayed a drive that
    cannot push, through a whole diagnosis to exit 0. The EMPS validation set saved as a CSV still loads."""
    for saturation in (1e-300, 0.0094):  # u = sin(t) reaches 0.0189989 at t = 19 ms
        meta = dict(META, controller=dict(META["controller"], saturation=saturation))
        with pytest.raises(InputError) as err:
            load_measured(_write(tmp_path, meta=meta))
        assert err.value.field.endswith("controller.saturation (run run)") and err.value.value == saturation
        assert "at least half the largest recorded |u|, 0.0189989 V at data row 20 of the run" in err.value.allowed
    for saturation in (0.0095, 0.019):  # a command added after the clip may pass it (EMPS validation pulses)
        meta = dict(META, controller=dict(META["controller"], saturation=saturation))
        assert load_measured(_write(tmp_path, meta=meta)).runs[0].n == 20
    validation = load_emps("validation")  # u = vir - pulses_N reaches 10.84 V at the 10 V saturation
    assert load_measured(save_measured(validation, tmp_path / "val.csv")[0]).runs[0].n == validation.runs[0].n


def test_a_params_file_that_is_no_yaml_is_named_once(tmp_path):
    """'rig.yaml: rig.yaml: got 'invalid YAML (line 2, column 1) ...'' named the file twice."""
    (tmp_path / "rig.yaml").write_text("not: [valid\n")
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, meta=dict(META, params="rig.yaml")))
    assert err.value.field == str(tmp_path / "rig.yaml") and "invalid YAML" in err.value.value


def test_position_columns_whose_travels_disagree_by_a_unit_are_refused(tmp_path):
    """A loop follows its reference and the table its motor: a thousand between two travels is a unit error."""
    n, dt = 2000, 1e-3
    t = np.arange(n) * dt
    x = 0.01 * (1 - np.cos(np.pi * t))
    x_motor = x - 1e-6 * np.sin(np.pi * t)
    cols = {"t": t, "x_ref": x, "x_motor": x_motor, "x_table": x_motor - 2e-6, "u": _law(x, x_motor)}
    assert load_measured(_write(tmp_path, cols)).run().n == n
    # x_ref in millimetres labelled m would move too fast: the slip the speed check cannot see is the other way,
    # a column in metres beside one written in millimetres and labelled mm (so read as a thousandth)
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, {**cols, "x_ref": 1e-3 * x}, name="ref.csv"))
    assert err.value.field.endswith("ref.csv: x_motor (run ref)") and "x_ref" in err.value.allowed
    assert "factor of 100 " in err.value.allowed and "unit" in err.value.allowed
    # a stick test of micrometres: the motor winds the screw up, the table hardly moves (30 times less) - let be
    assert load_measured(_write(tmp_path, {**cols, "x_table": x_motor / 30}, name="stick.csv")).run().n == n
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, {**cols, "x_table": 1e-3 * x}, name="table.csv"))
    assert err.value.field.endswith("x_table (run table)") and "x_motor" in err.value.allowed


def test_a_motor_encoder_that_reads_one_value_while_the_reference_travels_is_refused(tmp_path):
    """An unplugged encoder (or the wrong column): a zero travel is no travel to compare, and a whole diagnosis ran
    on a motor that never moved (found by the fuzzing pass)."""
    n, dt = 2000, 1e-3
    t = np.arange(n) * dt
    x = 0.01 * (1 - np.cos(np.pi * t))
    cols = {"t": t, "x_ref": x, "x_motor": 0 * t + 0.002, "u": np.sin(7 * t)}
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, cols))
    assert err.value.field.endswith("run.csv: x_motor (run run)")
    assert err.value.value == "constant while x_ref travels 0.02 m" and "unplugged" in err.value.allowed
    # a standstill (reference and motor both still) is not this error
    assert load_measured(_write(tmp_path, {**cols, "x_ref": 0 * t}, name="still.csv")).run().n == n
    # nor a stick test whose reference moves a few counts of a counting encoder that stays where it was
    counting = {**META, "sensors": {"encoder_resolution": 1e-6, "scale_resolution": 0.0}}
    small = {**cols, "x_ref": 0.002 + 5e-6 * (1 - np.cos(np.pi * t)) / 2}
    assert load_measured(_write(tmp_path, small, meta=counting, name="stick.csv")).run().n == n
    with pytest.raises(InputError, match="constant while x_ref travels"):  # 20 counts: it would have moved
        load_measured(_write(tmp_path, {**small, "x_ref": 0.002 + 2e-5 * (1 - np.cos(np.pi * t)) / 2},
                             meta=counting, name="moved.csv"))

def _segment(tmp_path, **controller):
    """The shipped EMPS segment with its controller metadata changed."""
    from drakecreep.data import example_path

    meta = yaml.safe_load(example_path("emps_segment.yaml").read_text())
    meta["controller"].update(controller)
    (tmp_path / "seg.yaml").write_text(yaml.safe_dump(meta))
    (tmp_path / "seg.csv").write_bytes(example_path("emps_segment.csv").read_bytes())
    return tmp_path / "seg.csv"


def test_declared_p_p_gains_the_recorded_command_contradicts_are_refused(tmp_path):
    run = load_measured(_segment(tmp_path)).run()  # as shipped: kp 160.18 1/s, kv 243.45 V per m/s
    kp, kv, lag, misfit = controller_gains(run)
    assert kp == pytest.approx(160.18, rel=0.05) and kv == pytest.approx(243.45, rel=0.1)
    assert lag == 0 and misfit < 0.05
    # a position gain of 1e-300 1/s ran a whole diagnosis of a loop without its position feedback
    with pytest.raises(InputError) as err:
        load_measured(_segment(tmp_path, kp=1e-300))
    assert err.value.field.endswith("controller.kp (run seg)") and err.value.value == 1e-300
    assert f"kp = {kp:.4g} 1/s" in err.value.allowed and "factor of 10" in err.value.allowed
    # kv per mm/s written for per m/s
    with pytest.raises(InputError) as err:
        load_measured(_segment(tmp_path, kv=0.24345))
    assert err.value.field.endswith("controller.kv (run seg)") and f"kv = {kv:.4g} V per m/s" in err.value.allowed
    # within the factor (a gain 3x off, or a delay of a few samples) the data are let be: the replay shows the rest
    assert load_measured(_segment(tmp_path, kp=3 * 160.18)).run().n == run.n
    late = MeasuredRun(t=run.t, x_ref=run.x_ref, x_motor=run.x_motor, u=np.r_[np.zeros(3), run.u[:-3]], meta=run.meta)
    assert controller_gains(late)[2] == 3 and controller_gains(late)[1] == pytest.approx(kv, rel=1e-3)


def test_a_command_that_is_not_the_p_p_form_says_nothing_about_the_gains():
    t = np.arange(400) * 1e-3
    x = 0.01 * t
    run = MeasuredRun(t=t, x_ref=x, x_motor=x - 1e-6 * np.cos(3 * t), u=np.random.default_rng(0).normal(size=t.size),
                      meta=MeasuredMeta(u_units="V", u_gain=35.0, controller=ControllerMeta(kp=100.0, kv=200.0)))
    assert controller_gains(run) is None


@pytest.mark.parametrize("train, test, said", [("abc", [], "train: got 'abc'; allowed: a list of MeasuredRun"),
                                               (None, [], "train: got None; allowed: a list of MeasuredRun"),
                                               ([], 5, "test: got 5; allowed: a list of MeasuredRun"),
                                               (["a"], [], "train: got 'a'; allowed: MeasuredRun items")])
def test_a_split_that_is_no_list_of_runs_is_named(train, test, said):
    """A script's diagnose_drive('abc', ...) ended in AttributeError: 'str' object has no attribute 'label'."""
    from drakecreep.gap.measured import check_split

    with pytest.raises(InputError) as err:
        check_split(train, test)
    assert str(err.value).startswith(said)


@pytest.mark.parametrize("key", ["source", "notes"])
def test_free_text_of_the_metadata_is_text(tmp_path, key):
    """A mapping or list under source/notes was kept as its Python repr ("{'rig': 'A'}") and saved so; an empty
    'notes:' was the text 'None'."""
    with pytest.raises(InputError) as err:
        load_measured(_write(tmp_path, meta=dict(META, **{key: {"rig": "A"}})))
    assert err.value.field == str(tmp_path / f"run.yaml: {key}") and err.value.value == "a YAML mapping"
    with pytest.raises(InputError, match=f"{key}: got 'a YAML list'; allowed: free text"):
        load_measured(_write(tmp_path, meta=dict(META, **{key: ["a", "b"]})))
    assert getattr(load_measured(_write(tmp_path, meta=dict(META, **{key: None}))).meta, key) == ""
    assert getattr(load_measured(_write(tmp_path, meta=dict(META, **{key: 2024}))).meta, key) == "2024"


def _fast_log(k=4, offset=3, held=True, n=200):
    """A P-P run whose 1 ms controller is logged every 1/k ms from ``offset`` samples before a tick: positions
    linear, ``u`` held over each tick (or, not ``held``, linear between ticks)."""
    from drakecreep.gap.measured import ControllerMeta, MeasuredMeta, MeasuredRun

    tick = np.arange(n) * 1e-3
    rng = np.random.default_rng(4)
    u_tick = np.cumsum(rng.normal(size=n))
    t = np.arange((n - 1) * k + 1) * (1e-3 / k)
    u = u_tick[np.minimum(np.floor(t / 1e-3 + 1e-9).astype(int), n - 1)] if held else np.interp(t, tick, u_tick)
    x = 0.05 * t
    meta = MeasuredMeta(u_units="V", u_gain=35.0, controller=ControllerMeta(kp=100.0, kv=200.0, sample_time=1e-3))
    return MeasuredRun(t=t[offset:], x_ref=x[offset:], x_motor=x[offset:], u=u[offset:], meta=meta, label="fast"), \
        u_tick


@pytest.mark.parametrize("offset", [0, 1, 3])
def test_a_log_taken_several_times_a_tick_is_cut_to_the_ticks_where_u_changes(offset):
    """The 1 ms controller logged every 0.25 ms, from any phase: the samples kept are the ticks (where the held
    ``u`` changes), one per millisecond, the label kept; :func:`load_runs` does it on loading."""
    from drakecreep.gap.measured import controller_ticks, on_controller_ticks

    run, u_tick = _fast_log(offset=offset)
    with pytest.raises(InputError, match="a log taken several times a tick goes through on_controller_ticks"):
        controller_ticks(run)
    ticks = on_controller_ticks(run)
    first = 1 if offset else 0  # the first whole tick logged
    assert ticks.label == "fast" and controller_ticks(ticks) == 1
    assert ticks.dt == pytest.approx(1e-3, rel=1e-9) and ticks.t[0] == pytest.approx(first * 1e-3, abs=1e-12)
    assert np.array_equal(ticks.u, u_tick[first: first + ticks.n])
    assert on_controller_ticks(ticks) is ticks


def test_a_fast_log_whose_u_changes_between_ticks_is_refused_naming_u():
    """A ``u`` that changes at every sample (a current, not the held command) does not say where the ticks are."""
    from drakecreep.gap.measured import on_controller_ticks

    run, _ = _fast_log(held=False)
    with pytest.raises(InputError, match=r"^u \(run fast\): got '2[0-9] % of its changes on one of the 4 samples of "
                                         r"a controller tick'; allowed: a command held between ticks"):
        on_controller_ticks(run)


def test_the_gains_of_a_log_taken_several_times_a_tick_are_checked_at_its_ticks(tmp_path):
    """The EMPS segment logged every 0.25 ms (positions linear, u held): its gains are fitted at the ticks, where
    the law holds (no lag, 1.0 % of u left, against 2 samples and 2.7 % on every sample), so the shipped gains
    pass and a kv per mm/s written for per m/s is still refused."""
    import dataclasses

    from drakecreep.gap.measured import check_recorded, on_controller_ticks

    run = load_measured(_segment(tmp_path)).run()
    k = 4
    fast_t = run.t[0] + np.arange((run.n - 1) * k + 1) * (run.dt / k)
    tick = np.minimum(np.arange(fast_t.size) // k, run.n - 1)
    slots = np.arange(fast_t.size) / k
    fast = MeasuredRun(t=fast_t, x_ref=np.interp(slots, np.arange(run.n), run.x_ref),
                       x_motor=np.interp(slots, np.arange(run.n), run.x_motor), u=run.u[tick], meta=run.meta,
                       label="fast")
    check_recorded(fast)
    kp, kv, lag, misfit = controller_gains(on_controller_ticks(fast))
    assert lag == 0 and misfit < 0.015 and kv == pytest.approx(243.45, rel=0.1)
    assert misfit < 0.5 * controller_gains(fast)[3]
    wrong = dataclasses.replace(run.meta, controller=dataclasses.replace(run.meta.controller, kv=0.24345))
    with pytest.raises(InputError) as err:
        check_recorded(dataclasses.replace(fast, meta=wrong))
    assert err.value.field == "controller.kv (run fast)" and "kv = " in err.value.allowed
