"""Smoke tests of the critical, hertz and modal subcommands through drakecreep.cli.main."""

import importlib.util
import json
import math

import numpy as np
import pytest

import drakecreep.cli as cli
from drakecreep.model.lumped import lumped
from drakecreep.paper.creep import critical_speed_of
from drakecreep.paper.modal import synthetic_hammer_test


@pytest.fixture(autouse=True)
def _only_importable_commands(monkeypatch):
    # other subcommands are being written concurrently; register the ones that exist
    present = [c for c in cli.COMMANDS if importlib.util.find_spec(f"drakecreep.cli.{c}")]
    monkeypatch.setattr(cli, "COMMANDS", present)


def run_json(capsys, argv):
    assert cli.main(argv + ["--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_critical_takes_the_presets_chain_and_load_case(capsys, paper):
    out = run_json(capsys, ["critical"])
    drive = lumped(paper, 3)
    assert out["inputs"]["load_case"] == 3
    assert out["inputs"]["stiffness_N_per_um"] == pytest.approx(drive.stiffness * 1e-6)
    assert out["inputs"]["Fd_N"] == pytest.approx(drive.coulomb)
    assert out["v0_self_consistent_mm_per_s"] == pytest.approx(critical_speed_of(drive) * 1e3)
    assert out["D0"] == pytest.approx(np.sqrt(4 * np.pi * out["zeta"]))
    # creep predicted exactly when the feed is below v0
    assert out["creep_predicted"] == (out["inputs"]["feed_mm_per_s"] < out["v0_mm_per_s"])
    # the same number the loop report gives for the preset (it reads the linearized operating point)
    unloaded = run_json(capsys, ["critical", "--load-case", "0"])
    assert unloaded["inputs"]["Fd_N"] < out["inputs"]["Fd_N"]


def test_critical_negative_damping_reports_no_v0(capsys):
    out = run_json(capsys, ["critical", "--damping", "0", "--feed", "0.01", "--friction", "stribeck",
                            "--preset", "paper"])
    assert out["C1_Ns_per_m"] < 0 and out["v0_mm_per_s"] is None and out["creep_predicted"]


def test_hertz_json_keys_and_paper_inputs(capsys):
    out = run_json(capsys, ["hertz"])
    for key in ("ka_N_per_m", "kr_N_per_m", "fa_Hz", "fr_Hz", "ball_load_N"):
        assert out[key] > 0
    assert out["ball_load_N"] == pytest.approx(17.457, rel=1e-3)
    more = run_json(capsys, ["hertz", "--preload", str(579 * 8)])
    assert more["ka_N_per_m"] == pytest.approx(2 * out["ka_N_per_m"], rel=1e-9)  # K ~ Fa^(1/3)


def test_modal_frf_csv(tmp_path, capsys):
    m, c, k = 0.335, 1.68, 1.62e5
    f = np.linspace(0, 300, 30001)
    H = 1 / (k - m * (2 * np.pi * f) ** 2 + 1j * c * 2 * np.pi * f)
    path = tmp_path / "frf.csv"
    np.savetxt(path, np.column_stack([f, H.real, H.imag]), delimiter=",", header="f_Hz,re,im",
               comments="")
    out = run_json(capsys, ["modal", str(path), "--mass", str(m)])
    assert out["half_power"]["k_N_per_m"] == pytest.approx(k, rel=0.01)
    assert out["sdof_fit"]["c_Ns_per_m"] == pytest.approx(c, rel=0.01)


def test_modal_time_csv(tmp_path, capsys):
    m, c, k, fs = 1.0, 258.28, 52.3e6, 50e3
    test = synthetic_hammer_test(m, c, k, fs, 0.2, 1e-4, delay=2e-4)
    path = tmp_path / "hit.csv"
    np.savetxt(path, np.column_stack([test.t, test.force[0], test.response[0]]), delimiter=",",
               header="t,force,response", comments="")
    out = run_json(capsys, ["modal", str(path), "--mass", "1.0"])
    assert out["sdof_fit"]["k_N_per_m"] == pytest.approx(k, rel=0.03)
    assert out["half_power"]["fn_Hz"] == pytest.approx(np.sqrt(k / m) / (2 * np.pi), rel=0.01)


@pytest.mark.parametrize("argv", [
    ["critical", "--mass", "-1"],
    ["hertz", "--conformity", "0.4"],
])
def test_bad_argument_exits_2_with_one_line(argv, capsys):
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "error" in err


def test_modal_bad_csv_header_exits_2(tmp_path, capsys):
    path = tmp_path / "bad.csv"
    path.write_text("a,b,c\n1,2,3\n")
    assert cli.main(["modal", str(path)]) == 2
    assert "f_Hz,re,im" in capsys.readouterr().err
    assert cli.main(["modal", str(tmp_path / "missing.csv")]) == 2


@pytest.mark.parametrize("kind, options, field", [
    ("time", ["--pulse-width", "-1"], "--pulse-width: got -1.0"),  # was blamed on the frequency band
    ("time", ["--pulse-width", "nan"], "--pulse-width: got nan"),
    # a window that cut the impulse changed the result (k 1.8e5 against 1.14e6 N/m), one that kept the whole record
    # did nothing, each without a word (found by fuzzing)
    ("time", ["--pulse-width", "1e-9"], "--pulse-width: got 1e-09; allowed: >= 4e-05 s, half the recorded impulse"),
    ("time", ["--pulse-width", "1"], "--pulse-width: got 1.0; allowed: <= 0.0167 s, a third of the record (0.05 s"),
    ("time", ["--exp-tau", "1e-9"], "--exp-tau: got 1e-09; allowed: >= 5.65e-05 s: the exponential window starts"),
    ("frf", ["--pulse-width", "1e-3"], "--pulse-width: got 0.001; allowed: only with a t,force,response file"),
    ("frf", ["--fmin", "nan"], "--fmin: got nan"),
    ("frf", ["--fmax", "inf"], "--fmax: got inf"),
    ("frf", ["--mass", "1e300"], "--mass: got 1e+300; allowed: a modal mass in [1e-06, 100000] kg"),  # k = 5e305
    ("frf", ["--mass", "1e-300"], "--mass: got 1e-300"),
    ("frf", ["--mass", "0"], "--mass: got 0.0"),
    # the band search said 'frequency band: got (200.0, 100.0)'; a negative end was taken as given
    ("frf", ["--fmin", "200", "--fmax", "100"], "--fmax: got 100.0; allowed: a frequency above --fmin (200 Hz)"),
    ("frf", ["--fmin", "100", "--fmax", "100"], "--fmax: got 100.0"),
    ("frf", ["--fmin", "-5"], "--fmin: got -5.0; allowed: a finite frequency >= 0 Hz"),
    # a band past the file's data said 'frequency band: got (5000.0, None)'
    ("frf", ["--fmin", "5000"], "--fmin: got 5000.0; allowed: a band with at least 3 FRF points (the file's f_Hz run "
                                "10-500 Hz"),
    ("frf", ["--fmax", "5"], "--fmax: got 5.0; allowed: a band with at least 3 FRF points (the file's f_Hz run 10-500"),
    # both ends given: the one outside the data, or the upper end of a band too narrow ('--fmin 0 --fmax 1e-9'
    # blamed --fmin)
    ("frf", ["--fmin", "0", "--fmax", "1e-9"], "--fmax: got 1e-09; allowed: a band with at least 3 FRF points"),
    ("frf", ["--fmin", "5000", "--fmax", "6000"], "--fmin: got 5000.0; allowed: a band with at least 3 FRF points"),
    # a window shorter than the data's decay: zeta = -0.82 (exit 0), at 1e-300 s an OverflowError (exit 1)
    ("frf", ["--exp-tau", "1e-3"], "--exp-tau: got 0.001; allowed: a longer window time constant: 1/tau = 1e+03 1/s"),
    ("frf", ["--exp-tau", "1e-300"], "--exp-tau: got 1e-300; allowed: a longer window time constant"),
    ("time", ["--exp-tau", "1e-4"], "--exp-tau: got 0.0001; allowed: a longer window time constant"),
    # a window that damps the mode beyond what half-power reads: 1 ms on a 300 Hz mode read it at 206 Hz, exit 0
    ("time", ["--exp-tau", "3e-4"], "--exp-tau: got 0.0003; allowed: a longer window time constant: the window's "
                                    "1/tau = 3.33e+03 1/s damps the windowed mode to zeta = "),
    # an option of the other kind of file was ignored without a word
    ("frf", ["--response", "velocity"], "--response: got 'velocity'; allowed: only with a t,force,response file"),
    ("time", ["--frf-type", "mobility"], "--frf-type: got 'mobility'; allowed: only with an f_Hz,re,im file"),
])
def test_modal_options_name_themselves(kind, options, field, tmp_path, capsys):
    path = tmp_path / "m.csv"
    if kind == "frf":
        f = np.linspace(10, 500, 200)
        H = 1 / (1e5 - (2 * np.pi * f) ** 2 + 20j * f)
        np.savetxt(path, np.column_stack([f, H.real, H.imag]), delimiter=",", header="f_Hz,re,im", comments="")
    else:
        test = synthetic_hammer_test(1.0, 258.28, 52.3e6, 50e3, 0.05, 1e-4, delay=2e-4)
        np.savetxt(path, np.column_stack([test.t, test.force[0], test.response[0]]), delimiter=",",
                   header="t,force,response", comments="")
    assert cli.main(["modal", str(path)] + options) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith(f"drakecreep modal: error: {field}")


@pytest.mark.parametrize("argv, field", [
    (["--stiffness", "1e-300"], "--stiffness"),  # these printed inf / 1e+148 with a RuntimeWarning, exit 0
    (["--stiffness", "1e300", "--mass", "1e-300"], "--stiffness"),
    (["--mass", "1e-300"], "--mass"),
    (["--damping", "1e300"], "--damping"),
    (["--fs", "1e308", "--fd", "1e308"], "--fs"),
    (["--feed", "1e300"], "--feed"),
])
def test_critical_refuses_overflowing_values(argv, field, capsys):
    assert cli.main(["critical", "--json"] + argv) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert captured.out == "" and err.count("\n") == 0 and err.startswith(f"drakecreep critical: error: {field}: got")


@pytest.mark.parametrize("argv, line", [
    # the unit of the option (N/um, not the model's N/m) in what is allowed
    (["--stiffness", "-1"], "--stiffness: got -1.0; allowed: a number in [1e-06, 1e+14] N/um"),
    (["--damping", "-5"], "--damping: got -5.0; allowed: a number in [0, 1e+08] N s/m"),
    (["--mass", "0"], "--mass: got 0.0; allowed: a number in [0.001, 100000] kg"),
    # the ranges of the parameter fields they stand for: these were accepted and printed a boundary of no drive
    (["--stiffness", "1e-26", "--mass", "2"], "--stiffness: got 1e-26; allowed: a number in [1e-06, 1e+14] N/um"),
    (["--mass", "1e-20"], "--mass: got 1e-20; allowed: a number in [0.001, 100000] kg"),
    (["--damping", "1e12"], "--damping: got 1000000000000.0; allowed: a number in [0, 1e+08] N s/m"),
    (["--fs", "1e20"], "--fs: got 1e+20; allowed: a number in [1e-06, 1e+06] N"),
    # --fd above the parameters' Fs named --fd, not '--fs: got 12.234376764999999', an option not given
    (["--fd", "100"], "--fd: got 100.0; allowed: <= Fs (12.2344 N, the parameters' breakaway; or give --fs)"),
    (["--fs", "1", "--fd", "2"], "--fs: got 1.0; allowed: >= Fd (2 N)"),
])
def test_critical_names_the_option_given_in_its_unit(argv, line, capsys):
    assert cli.main(["critical"] + argv) == 2
    assert capsys.readouterr().err.strip() == f"drakecreep critical: error: {line}"


def test_critical_at_the_bounds_is_finite(capsys):
    assert cli.main(["critical", "--json", "--stiffness", "1e14", "--mass", "1e-3", "--damping", "0"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert math.isfinite(out["natural_frequency_Hz"]) and math.isfinite(out["zeta"])


def test_critical_gives_no_verdict_where_the_drive_cannot_hold_the_feed(tmp_path, capsys):
    """A 0.1 N m drive at 50 mm/s (136 N of friction against a 126 N limit) was 'creep at v: no', as 1e6 N of load
    was: the drive that cannot slide gets no verdict, as in simulate; at 1 mm/s it slides and keeps its verdict."""
    (tmp_path / "weak.yaml").write_text("motor: {peak_torque: 0.1}\n")
    base = ["critical", "--params", str(tmp_path / "weak.yaml"), "--load-case", "0"]
    out = run_json(capsys, base + ["--feed", "50"])
    assert out["creep_predicted"] is None and out["overload"]["force_N"] > out["overload"]["limit_N"]
    assert out["overload"]["limit_N"] == pytest.approx(2 * math.pi * 0.1 / 5e-3)
    slow = run_json(capsys, base)
    assert slow["creep_predicted"] is False and "overload" not in slow
    # a what-if of the lumped drive's friction is not held to the parameters' drive
    assert run_json(capsys, base + ["--feed", "50", "--fs", "2", "--fd", "1"])["creep_predicted"] is not None
