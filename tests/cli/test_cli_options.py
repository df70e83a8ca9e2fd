import json

import pytest
import yaml

from drakecreep import cli
from drakecreep.params import load_params


def _subparsers():
    parser = cli.build_parser()
    action = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return parser, action.choices


def test_quiet_and_verbose_before_or_after_the_command():
    parser = cli.build_parser()
    assert parser.parse_args(["-q", "hertz"]).quiet and parser.parse_args(["hertz", "-q"]).quiet
    assert not parser.parse_args(["hertz"]).quiet
    assert parser.parse_args(["-vv", "hertz"]).verbose == 2 and parser.parse_args(["hertz", "-v"]).verbose == 1


def test_heartbeat_appears_on_stderr_for_a_long_job_and_not_with_quiet(monkeypatch, capsys):
    import time

    import drakecreep.cli.hertz as hertz

    def slow(args):  # a job longer than the heartbeat's wait (2 s in use, 0.2 s here) and three of its ticks
        time.sleep(1.5)
        return 0

    monkeypatch.setattr(cli, "HEARTBEAT", ("hertz",))
    monkeypatch.setattr(cli, "HEARTBEAT_AFTER", 0.2)
    monkeypatch.setenv("DRAKECREEP_PROGRESS", "1")  # stderr is not a terminal under pytest: force it
    monkeypatch.setattr(hertz, "run", slow)
    assert cli.main(["hertz"]) == 0
    err = capsys.readouterr().err
    assert "drakecreep hertz: 00:0" in err and "elapsed" in err
    assert cli.main(["-q", "hertz"]) == 0
    assert "elapsed" not in capsys.readouterr().err
    monkeypatch.delenv("DRAKECREEP_PROGRESS")
    assert cli.main(["hertz"]) == 0
    assert "elapsed" not in capsys.readouterr().err  # not a terminal: one line per message in logs


def test_tune_write_gives_a_file_simulate_accepts(tmp_path, capsys):
    path = tmp_path / "tuned.yaml"
    assert cli.main(["-q", "tune", "--bandwidth", "30", "--write", str(path), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    params = load_params(path)
    assert params.controller.velocity_gain == pytest.approx(summary["velocity_gain_Ns_per_m"], rel=1e-12)
    assert summary["params_file"] == str(path)
    assert isinstance(yaml.safe_load(path.read_text()), dict)
    out = tmp_path / "sim"
    assert cli.main(["-q", "simulate", "--params", str(path), "--duration", "1.2", "--no-plot", "--out", str(out),
                     "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["status"] == "ok"


@pytest.mark.parametrize("name", ["simulate", "critical", "hertz", "modal", "margins", "tune", "report", "emps",
                                  "reproduce-paper", "compensate", "diagnose", "gap-benchmark"])
def test_every_computing_command_has_json(name):
    _, commands = _subparsers()
    assert "--json" in commands[name].format_help()


def test_every_command_documents_quiet_and_verbose():
    parser, commands = _subparsers()
    for name, sub in [("drakecreep", parser), *commands.items()]:
        text = sub.format_help()
        assert "-q, --quiet" in text and "-v, --verbose" in text, name


@pytest.mark.parametrize("args, option", [(["--bandwidth", "-5"], "--bandwidth"), (["--phase-margin", "95"], "--phase-margin")])
def test_tune_refuses_bad_targets_before_any_work(args, option, capsys, monkeypatch):
    import drakecreep.cli.margins
    import drakecreep.servo.tuning

    def no_work(*a, **k):
        raise AssertionError("the targets must be checked before the operating point and the tuning")

    monkeypatch.setattr(drakecreep.servo.tuning, "tune", no_work)
    monkeypatch.setattr(drakecreep.cli.margins, "scenario_from_args", no_work)
    assert cli.main(["tune", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"error: {option}: got" in err[0]


def _valued_options():
    _, commands = _subparsers()
    return [(name, a.option_strings[-1]) for name, sub in commands.items() for a in sub._actions
            if a.option_strings and a.nargs is None and a.type is not None and a.choices is None]


@pytest.mark.parametrize("value", ["-1e-3", "-1E+3", "-2.5e1", "-inf", "-1e-3,2", "-1,,2"])
def test_a_negative_number_in_exponent_form_is_a_value_not_an_option(value, capsys):
    """argparse (3.11) takes '-1e-3' for an option: 'modes --table-position -1e-3' ended in 'argument
    --table-position: expected one argument' while -0.001 ran; every option with a value reads it now."""
    parser = cli.build_parser()
    assert parser.parse_args(["modes", "--table-position", "-1e-3"]).table_position == -1e-3
    options = _valued_options()
    assert len(options) > 40
    for name, option in options:
        extra = ["x"] if name in ("sweep", "modal", "diagnose") else []
        try:
            parser.parse_args([name, option, value, *extra])
        except SystemExit:
            pass
        err = capsys.readouterr().err
        assert "expected one argument" not in err, (name, option, err)
    with pytest.raises(SystemExit):  # options are still options
        parser.parse_args(["modes", "--table-position", "-q"])


def test_the_parser_of_every_command_is_built_without_the_libraries_behind_it():
    """``drakecreep --help`` and a mistyped option took 3.4-3.8 s (session 65): building the parser imported
    Drake, SciPy and pandas through five commands' modules (critical, hertz, modal, modes, gap-benchmark). The
    commands import what they compute with when they run; the parser needs none of it (0.3 s)."""
    import subprocess
    import sys

    code = ("import sys; from drakecreep.cli import build_parser; build_parser(); "
            "print(' '.join(m for m in ('pydrake', 'scipy', 'pandas', 'matplotlib', 'control') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == ""
