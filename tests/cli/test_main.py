import json

import pytest
import yaml

from drakecreep.cli import main


def test_simulate_json(tmp_path, capsys):
    code = main(["simulate", "--feed", "0.2", "--duration", "1.5", "--load-case", "1", "--out", str(tmp_path), "--json",
                 "--no-plot"])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("mean_speed_mm_s", "max_fluctuation_mm_s", "fluctuation_rate_percent", "stick_fraction",
                "stick_slip_cycles", "sim_time_s", "wall_time_s"):
        assert key in out
    assert out["stick_slip_cycles"] > 0 and out["mean_speed_mm_s"] == pytest.approx(0.2, rel=0.01)
    assert (tmp_path / "timeseries.csv").exists() and (tmp_path / "metrics.json").exists()


def test_simulate_text(tmp_path, capsys):
    assert main(["simulate", "--feed", "2", "--duration", "1.2", "--friction", "stribeck", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "max speed fluctuation" in out
    creep_line = next(line for line in out.splitlines() if "creep (stick-slip)" in line)
    assert creep_line.split()[-1] == "no"
    assert (tmp_path / "speed.png").exists()


@pytest.mark.parametrize("argv, fragment", [
    (["simulate", "--feed", "abc"], "--feed"),
    (["simulate", "--feed", "0"], "--feed"),
    (["simulate", "--load-case", "9"], "--load-case"),
    (["simulate", "--duration", "0.5"], "--duration"),
    (["simulate", "--friction", "maxwell"], "--friction"),
    (["simulate", "--params", "/no/such/file.yaml"], "--params: got '/no/such/file.yaml'; allowed: an existing file"),
    (["diagram", "--out", "x.jpg"], "--out"),
    (["nonsense"], "drakecreep: error: COMMAND: got 'nonsense'; allowed: one of simulate, params, diagram"),
    # argparse's own refusals of a value, in the refusals' form: the option, what it got, what it allows
    (["critical", "--feed", "abc"], "drakecreep critical: error: --feed: got 'abc'; allowed: a number"),
    (["uncertainty", "--seed", "x"], "drakecreep uncertainty: error: --seed: got 'x'; allowed: an integer"),
    (["simulate", "--friction", "maxwell"],
     "--friction: got 'maxwell'; allowed: one of coulomb, stribeck, lugre, gms"),
    (["simulate", "--feed"], "drakecreep simulate: error: --feed: got nothing; allowed: one value after the option"),
    (["gap-benchmark", "--kinds"], "--kinds: got nothing; allowed: at least one value after the option"),
    # an option of no command: the command's own parser names itself and where its options are listed
    (["margins", "--speed", "abc"], "drakecreep margins: error: unrecognized arguments: --speed abc "
                                    "(drakecreep margins --help lists the options)"),
    # an abbreviation is refused, not guessed (--dur would be --duration, --n would be --no-progress)
    (["simulate", "--dur", "1"], "unrecognized arguments: --dur 1"),
    (["uncertainty", "--n", "0"], "unrecognized arguments: --n 0"),
    # no command: an unknown option is named before the missing command
    (["--vers"], "drakecreep: error: unrecognized arguments: --vers"),
    (["-vv"], "the following arguments are required: COMMAND"),
])
def test_bad_arguments_one_line_exit_2(argv, fragment, capsys, tmp_path):
    try:
        code = main(argv + (["--out", str(tmp_path / "o")] if argv[0] == "simulate" else []))
    except SystemExit as exit_:
        code = exit_.code
    err = capsys.readouterr().err
    assert code == 2
    assert fragment in err and len(err.strip().splitlines()) == 1


def test_argparse_messages_other_than_a_refused_value_stay_as_they_are():
    from drakecreep.cli import _refusal

    message = "argument --params: not allowed with argument --preset"
    assert _refusal(message) == message
    required = "the following arguments are required: SPEC.yaml"
    assert _refusal(required) == required


def test_bad_parameter_file(tmp_path, capsys):
    path = tmp_path / "bad.yaml"
    path.write_text("table: {mass: -3}\n")
    assert main(["simulate", "--params", str(path), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "table.mass" in err and "-3" in err and "[0.001, 100000.0] kg" in err


def test_params_prints_loadable_yaml(tmp_path, capsys):
    assert main(["params", "--preset", "paper"]) == 0
    text = capsys.readouterr().out
    assert "[assumed]" in text
    path = tmp_path / "p.yaml"
    path.write_text(text)
    assert main(["params", "--check", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["screw"]["lead"] == 0.005
    assert yaml.safe_load(text)["nut"]["axial_damping"] == 898.88


def test_diagram_of_a_params_file_without_load_cases(tmp_path, capsys):
    """'load_case: got 3' named an option diagram does not have; the drawing does not depend on the load case."""
    (tmp_path / "p.yaml").write_text("screw: {lead: 0.005}\n")  # defaults but the lead: no load cases
    assert main(["diagram", "--params", str(tmp_path / "p.yaml"), "--out", str(tmp_path / "d.dot")]) == 0
    assert "CascadeController" in (tmp_path / "d.dot").read_text()
    capsys.readouterr()


def test_diagram_dot_and_svg(tmp_path):
    assert main(["diagram", "--out", str(tmp_path / "d.dot")]) == 0
    assert "CascadeController" in (tmp_path / "d.dot").read_text()
    import shutil

    if shutil.which("dot") is None:
        pytest.skip("Graphviz 'dot' not installed")
    assert main(["diagram", "--out", str(tmp_path / "d.svg")]) == 0
    assert (tmp_path / "d.svg").read_text().lstrip().startswith("<?xml")


def test_diagram_says_which_controller_it_draws(tmp_path, capsys):
    """The controller is one block either way: --controller continuous drew the same picture as sampled."""
    texts = {}
    for variant in ("sampled", "continuous"):
        assert main(["diagram", "--controller", variant, "--out", str(tmp_path / f"{variant}.dot")]) == 0
        texts[variant] = (tmp_path / f"{variant}.dot").read_text()
    assert ('label="preset paper: sampled PI cascade controller: velocity loop every 0.25 ms, position loop every '
            '1 ms, computation delay 1 velocity samples"') in texts["sampled"]
    assert 'label="preset paper: continuous PI cascade controller"' in texts["continuous"]
    assert main(["diagram", "--out", str(tmp_path / "default.dot")]) == 0
    assert "sampled PI cascade" in (tmp_path / "default.dot").read_text()  # the preset's variant
    assert not list(tmp_path.glob(".*"))  # written atomically: no temporary file left
    capsys.readouterr()


def test_params_check_and_preset_are_one_or_the_other(tmp_path, capsys):
    """'params --check FILE --preset rigid_axis' printed the file and ignored the preset without a word."""
    from drakecreep.params import preset, save_params

    save_params(preset("paper"), tmp_path / "p.yaml")
    with pytest.raises(SystemExit) as stop:
        main(["params", "--check", str(tmp_path / "p.yaml"), "--preset", "rigid_axis"])
    err = capsys.readouterr().err.strip().splitlines()
    assert stop.value.code == 2 and "not allowed with argument" in err[-1]
    assert main(["params", "--check", str(tmp_path / "p.yaml")]) == 0 and main(["params", "--json"]) == 0
    capsys.readouterr()


@pytest.mark.parametrize("command", [["simulate", "--out", "{tmp}/o"], ["critical"]])
def test_a_params_file_without_load_cases_says_so_for_the_default_load_case(command, tmp_path, capsys):
    """A params file of only a controller section said 'allowed: an integer in 0..0' for the default case 3."""
    path = tmp_path / "gains.yaml"
    path.write_text("controller: {velocity_gain: 1.0e5}\n")
    assert main([a.format(tmp=tmp_path) for a in command] + ["--params", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--load-case: got 3; allowed: 0 (unloaded): these parameters define no load cases" in err[0]
