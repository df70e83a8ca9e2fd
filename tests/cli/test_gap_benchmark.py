import json

import pytest

from drakecreep import cli
from drakecreep.errors import InputError


def test_gap_benchmark_json_on_one_short_null(capsys, tmp_path):
    """One short null through the product diagnosis (one candidate, to stay fast), kept in ``--out``: the same
    command again resumes from its rows (nothing diagnosed again), other settings in that folder are refused."""
    command = ["gap-benchmark", "--seeds", "dev", "--n-per-effect", "0", "--effects", "position_ripple",
               "--n-null", "1", "--n-ool", "0", "--samples", "600", "--json", "--out", str(tmp_path / "run")]
    assert cli.main(command) == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert data["scores"]["n_datasets"] == 1
    row = data["datasets"][0]
    assert row["category"] == "null" and row["kind"] == "p_p_cascade" and row["claimed"] == []
    assert [r["effect"] for r in row["ranking"]] == ["position_ripple"]
    assert row["audit"]["nominal"]["force_rms"] > 0
    # no claim: no shrink, and the audit of the claimed model is the nominal's (tests/gap/test_benchmark.py ran a
    # second null for these until session 64)
    assert row["audit_shrink"] == 0.0 and row["audit"]["claimed"] == row["audit"]["nominal"]
    assert "[gap-benchmark] 1/1 seed" in captured.err
    # the folder: the rows with their settings, the results, a manifest; the checkpoints' folder empty again
    kept = json.loads((tmp_path / "run" / "rows.json").read_text())
    assert kept["complete"] is True and kept["datasets"] == data["datasets"] and kept["settings"]["n_null"] == 1
    assert json.loads((tmp_path / "run" / "results.json").read_text())["scores"] == data["scores"]
    assert (tmp_path / "run" / "manifest.json").exists() and not any((tmp_path / "run" / "checkpoints").iterdir())
    assert cli.main(command) == 0
    again = capsys.readouterr()
    assert json.loads(again.out)["datasets"] == data["datasets"]
    assert "1 datasets diagnosed in it" in again.err and "diagnosed in the earlier run" in again.err
    command[command.index("--n-null") + 1] = "2"
    assert cli.main(command) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"drakecreep gap-benchmark: error: --out: got '{tmp_path / 'run'}'")
    assert "a run with the same settings (it holds one with n_null 1)" in err[0]
    (tmp_path / "run" / "rows.json").write_text("{not json")
    assert cli.main(command) == 2
    assert "rows.json is one this command wrote" in capsys.readouterr().err


def test_gap_benchmark_rejects_bad_arguments(capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["gap-benchmark", "--n-null", "-1"])
    assert exc.value.code == 2
    # in the refusals' own form ('... must be >= 0' where --n-null 1001 said '--n-null: got 1001; allowed: ...'), and
    # one range said one way ('an integer >= 0' for -1, 'an integer in [0, 1000]' for 1001)
    assert capsys.readouterr().err.strip() == ("drakecreep gap-benchmark: error: --n-null: got '-1'; allowed: an "
                                               "integer in [0, 1000]")
    for option, bad, allowed in (("--n-ool", "1001", "[0, 1000]"), ("--samples", "-3", "[600, 1000000]"),
                                 ("--samples", "599", "[600, 1000000]")):
        with pytest.raises(SystemExit):
            cli.main(["gap-benchmark", option, bad])
        assert capsys.readouterr().err.strip().endswith(f"{option}: got '{bad}'; allowed: an integer in {allowed}")


def test_the_help_names_every_kind_and_the_default_the_run_takes(capsys, monkeypatch):
    """The parser imports nothing of the library (a second of SciPy and Drake for every --help), so its help names
    the kinds in words: held here to the library's list, and the run without --kinds to its default."""
    from drakecreep.gap import benchmark

    with pytest.raises(SystemExit):
        cli.main(["gap-benchmark", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert all(kind in text for kind in benchmark.BENCHMARK_KINDS)
    assert f"{benchmark.DEFAULT_KINDS[0]} (the default)" in text and len(benchmark.DEFAULT_KINDS) == 1
    seen = {}

    def started(**kwargs):
        seen.update(kwargs)
        raise InputError("stop", "here", "no benchmark in this test")

    monkeypatch.setattr(benchmark, "run_benchmark", started)
    assert cli.main(["gap-benchmark", "--n-null", "1"]) == 2
    assert seen["kinds"] == benchmark.DEFAULT_KINDS


def test_gap_benchmark_rejects_short_runs_before_work(capsys):
    with pytest.raises(SystemExit) as exc:  # by its argparse type: before anything of the library is imported
        cli.main(["gap-benchmark", "--samples", "10"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--samples" in err


@pytest.mark.parametrize("argv, needle", [(["--kinds", "pid"], "--kinds: got 'pid'; allowed: one of p_p_cascade"),
                                          (["--effects", "gremlins"], "--effects"),
                                          (["--effects", "backlash"], "--effects"),
                                          (["--kinds", "drakecreep", "--effects", "drive_gain"], "--effects"),
                                          (["--kinds", "drakecreep", "p_p_cascade", "--effects", "stribeck"],
                                           "one --kinds"),
                                          (["--mass-spread", "0.15"], "--mass-spread: got 0.15; allowed: 0 unless"),
                                          (["--kinds", "drakecreep", "--mass-spread", "-0.1"], "--mass-spread: got")])
def test_gap_benchmark_rejects_what_it_cannot_benchmark_before_work(capsys, argv, needle):
    assert cli.main(["gap-benchmark"] + argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err


@pytest.mark.parametrize("argv, field", [(["--n-per-effect", "999999999"], "--n-per-effect"),
                                         (["--n-null", "5000"], "--n-null"),
                                         (["--n-ool", "99999"], "--n-ool"),
                                         (["--samples", "99999999999"], "--samples"),
                                         # each null and out-of-library dataset was drawn, diagnosed and scored twice
                                         (["--kinds", "p_p_cascade", "p_p_cascade", "--n-per-effect", "1"], "--kinds"),
                                         (["--kinds", "drakecreep", "p_p_cascade", "drakecreep"], "--kinds"),
                                         (["--kinds", "drakecreep", "--mass-spread", "x"], "--mass-spread"),
                                         (["--kinds", "drakecreep", "--mass-spread", "0.51"], "--mass-spread")])
def test_gap_benchmark_refuses_sizes_that_never_end_before_starting(capsys, monkeypatch, argv, field):
    import drakecreep.gap.benchmark as benchmark

    def started(**kwargs):
        raise AssertionError("the benchmark started")

    monkeypatch.setattr(benchmark, "run_benchmark", started)
    try:  # the sizes by their argparse type, the kinds when the run starts
        code = cli.main(["gap-benchmark"] + argv)
    except SystemExit as exit_:
        code = exit_.code
    assert code == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and err.startswith(f"drakecreep gap-benchmark: error: {field}: got ")


def test_check_kinds_refuses_a_kind_twice():
    from drakecreep.errors import InputError
    from drakecreep.gap.benchmark import check_kinds

    assert check_kinds(["drakecreep", "p_p_cascade"]) == ("drakecreep", "p_p_cascade")
    for kinds, allowed in ((("p_p_cascade", "p_p_cascade"), "each kind once (p_p_cascade is there twice)"),
                           ((), "one or more of"), (("pid",), "one of")):
        with pytest.raises(InputError) as err:
            check_kinds(kinds)
        assert err.value.field == "kinds" and allowed in err.value.allowed
