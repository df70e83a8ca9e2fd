import json

import pytest

from drakecreep.cli import main
from drakecreep.report.loop_report import build_report


@pytest.fixture(scope="module")
def report(paper, tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    return build_report(paper, out, sim_grid=(2, 2), map_size=(4, 5))


def test_report_is_self_contained(report):
    text = report["html"].read_text()
    assert text.count("data:image/png;base64,") == 6
    assert 'src="http' not in text and "<script" not in text
    for fragment in ("Parameters used", "gain margin (dB)", "phase margin (deg)", "delay margin (ms)",
                     "sensitivity peak Ms", "Bode", "Nyquist", "Root locus", "Pole map", "D<sup>2</sup> = 4 pi zeta",
                     "Critical speed", "low-speed feed"):
        assert fragment in text
    assert "@@TOTAL@@" not in text


def test_report_json(report):
    data = json.loads(report["json"].read_text())
    for loop in ("velocity", "position"):
        assert data["margins"][loop]["closed_loop_stable"] is True
    assert data["critical_speed_mm_s"] > 0


def test_report_critical_speed_is_the_critical_commands(report, capsys):
    """One eq. 11 in the product: the report's v0 is 'drakecreep critical''s (the friction on the moving mass as
    the model applies it), not the linearization's, which lumps the nut's drag on the table (8.7 mm/s against
    0.52 mm/s on the paper preset before they were one)."""
    data = json.loads(report["json"].read_text())
    assert main(["critical", "--load-case", "3", "--feed", "1", "--json"]) == 0
    cli = json.loads(capsys.readouterr().out)
    assert data["critical_speed_mm_s"] == pytest.approx(cli["v0_mm_per_s"], rel=1e-12)
    assert data["critical_speed_self_consistent_mm_s"] == pytest.approx(cli["v0_self_consistent_mm_per_s"], rel=1e-12)
    text = report["html"].read_text()
    assert f"Fs {cli['inputs']['Fs_N']:.4g} N, Fd {cli['inputs']['Fd_N']:.4g} N" in text
    assert data["low_feed"]["stick_fraction"] > 0  # the preset creeps at 0.1 mm/s
    # its time is reported (analysis/bench_report.py measures it against a baseline; no timed test here)
    assert report["timings"]["total"] > 0


KEYS = ("gain_margin_dB", "phase_margin_deg", "delay_margin_ms", "crossover_Hz", "bandwidth_Hz", "ms_peak")


def test_cli_margins_json(capsys):
    assert main(["margins", "--feed", "1", "--load-case", "2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for loop in ("velocity", "position"):
        for key in KEYS:
            assert isinstance(out[loop][key], float)
    assert out["controller"] == "sampled" and "continuous" in out


def test_cli_margins_text(capsys):
    assert main(["margins", "--friction", "stribeck"]) == 0
    out = capsys.readouterr().out
    assert "phase margin (deg)" in out and "phase lost to sampling" in out


def test_cli_tune_json(capsys):
    assert main(["tune", "--bandwidth", "30", "--phase-margin", "50", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["velocity"]["phase_margin_deg"] == pytest.approx(50.0, abs=1e-3)
    assert out["velocity_gain_Ns_per_m"] > 0


@pytest.mark.parametrize("argv, fragment", [
    (["margins", "--feed", "abc"], "--feed"),
    (["margins", "--feed", "0"], "--feed"),
    (["margins", "--load-case", "7"], "--load-case"),
    (["tune", "--phase-margin", "120"], "--phase-margin"),
    (["tune", "--bandwidth", "5000"], "--bandwidth"),
    (["report"], "--out"),
    (["report", "--out", "x", "--low-feed", "0"], "--low-feed"),
])
def test_cli_bad_arguments_exit_2(argv, fragment, capsys):
    try:
        code = main(argv)
    except SystemExit as exit_:
        code = exit_.code
    err = capsys.readouterr().err
    assert code == 2
    assert fragment in err and len(err.strip().splitlines()) == 1
