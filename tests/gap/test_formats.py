import numpy as np
import pandas as pd
import pytest
import scipy.io
import yaml

from drakecreep.data import example_path
from drakecreep.errors import InputError
from drakecreep.gap.formats import parse_name, read_table
from drakecreep.gap.measured import load_measured

META = {"u_units": "V", "u_gain": 35.0, "controller": {"kind": "p_p_cascade", "kp": 100.0, "kv": 200.0,
                                                       "saturation": 10.0, "sample_time": 0.001}}


def _si(n=50):
    t = np.arange(n) * 1e-3
    return {"t": t, "x_ref": 0.01 + 2e-3 * t, "x_motor": 0.01 + 2e-3 * t - 3e-7 * np.sin(50 * t), "u": np.cos(t)}


@pytest.mark.parametrize("text, name, factor", [("t[ms]", "t", 1e-3), ("t (s)", "t", 1.0), ("x_motor[um]", "x_motor", 1e-6),
                                                ("x_ref[µm]", "x_ref", 1e-6), ("x_table[nm]", "x_table", 1e-9),
                                                ("u[mV]", "u", 1e-3), ("f_ext[kN]", "f_ext", 1e3), ("run", "run", 1.0)])
def test_parse_name(text, name, factor):
    assert parse_name(text, "f", "V") == (name, factor)


@pytest.mark.parametrize("text, unit, allowed", [("x_motor[inch]", "inch", "m, mm, um"), ("t[h]", "h", "s, ms, us"),
                                                 ("u[A]", "A", "V, mV"), ("f_ext[lbf]", "lbf", "N, kN")])
def test_unknown_unit_names_column_unit_and_allowed(text, unit, allowed):
    with pytest.raises(InputError) as err:
        parse_name(text, "file.csv", "V")
    assert text.split("[")[0] in err.value.field and err.value.value == unit and allowed in err.value.allowed


def test_csv_in_mm_and_ms_equals_si(tmp_path):
    si = _si()
    pd.DataFrame(si).to_csv(tmp_path / "si.csv", index=False, float_format="%.17g")
    pd.DataFrame({"t[ms]": si["t"] * 1e3, "x_ref[mm]": si["x_ref"] * 1e3, "x_motor[um]": si["x_motor"] * 1e6,
                  "u[mV]": si["u"] * 1e3}).to_csv(tmp_path / "mm.csv", index=False, float_format="%.17g")
    for name in ("si", "mm"):
        (tmp_path / f"{name}.yaml").write_text(yaml.safe_dump(META))
    a, b = load_measured(tmp_path / "si.csv").run(), load_measured(tmp_path / "mm.csv").run()
    for col in ("t", "x_ref", "x_motor", "u"):
        np.testing.assert_allclose(getattr(b, col), getattr(a, col), rtol=1e-14, atol=1e-18)


def test_parquet_and_hdf5(tmp_path):
    import h5py

    si = _si()
    pd.DataFrame({"t[ms]": si["t"] * 1e3, "x_ref": si["x_ref"], "x_motor[mm]": si["x_motor"] * 1e3,
                  "u": si["u"]}).to_parquet(tmp_path / "run.parquet")
    with h5py.File(tmp_path / "run.h5", "w") as fh:
        fh["t[ms]"] = si["t"] * 1e3
        for col in ("x_ref", "x_motor", "u"):
            fh[col] = si[col]
    for name in ("run.parquet", "run.h5"):
        (tmp_path / name).with_suffix(".yaml").write_text(yaml.safe_dump(META))
        run = load_measured(tmp_path / name).run()
        np.testing.assert_allclose(run.t, si["t"], rtol=1e-14, atol=1e-18)
        np.testing.assert_allclose(run.x_motor, si["x_motor"], rtol=1e-14)


def test_mat_with_column_mapping(tmp_path):
    si = _si()
    scipy.io.savemat(tmp_path / "logger.mat", {"time": si["t"][:, None], "ref_mm": si["x_ref"][:, None] * 1e3,
                                               "enc_um": si["x_motor"][:, None] * 1e6, "vir": si["u"][:, None],
                                               "kp": 100.0})
    meta = dict(META, columns={"t[s]": "time", "x_ref[mm]": "ref_mm", "x_motor[um]": "enc_um", "u[V]": "vir"})
    (tmp_path / "logger.yaml").write_text(yaml.safe_dump(meta))
    run = load_measured(tmp_path / "logger.mat").run()
    np.testing.assert_allclose(run.x_ref, si["x_ref"], rtol=1e-14)
    np.testing.assert_allclose(run.x_motor, si["x_motor"], rtol=1e-14)
    meta["columns"]["u[V]"] = "volts"
    (tmp_path / "logger.yaml").write_text(yaml.safe_dump(meta))
    with pytest.raises(InputError, match="one of") as err:
        load_measured(tmp_path / "logger.mat")
    assert err.value.field == "columns: u[V]" and err.value.value == "volts"


def test_not_a_number_and_bad_suffix(tmp_path):
    (tmp_path / "a.csv").write_text("t,x_ref,x_motor,u\n0,0,0,0\n0.001,0,abc,0\n0.002,0,0,0\n")
    with pytest.raises(InputError, match="abc") as err:
        read_table(tmp_path / "a.csv", "V")
    assert "x_motor" in err.value.field
    (tmp_path / "a.xlsx").write_text("")
    with pytest.raises(InputError, match=".parquet"):
        read_table(tmp_path / "a.xlsx", "V")


def test_shipped_example_is_mm_and_ms_converted_to_si():
    path = example_path("measured_mm_ms.csv")
    raw = pd.read_csv(path, comment="#")
    assert list(raw.columns) == ["t[ms]", "x_ref[mm]", "x_motor[mm]", "u[V]", "run"]
    data = load_measured(path)
    assert data.labels == ("r0", "r1", "r2", "r3")
    r0 = raw[raw["run"] == "r0"]
    run = data.run("r0")
    np.testing.assert_allclose(run.t, r0["t[ms]"].to_numpy() / 1e3, rtol=1e-15)
    np.testing.assert_allclose(run.x_motor, r0["x_motor[mm]"].to_numpy() / 1e3, rtol=1e-15)
    assert run.dt == pytest.approx(1e-3) and 0.005 < run.x_motor.max() < 0.1  # metres, not mm
    assert path.stat().st_size < 500e3
