"""The analysis scripts are run by users from the command line: each parses its arguments, so ``--help`` prints
its usage instead of starting the long job, and a wrong argument is refused with exit status 2."""

import ast
import importlib.util
import json
import math
import os
import pkgutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from drakecreep.gap.benchmark import HELDOUT_SEEDS

ANALYSIS = Path(__file__).resolve().parents[1] / "analysis"
SCRIPTS = sorted(p for p in ANALYSIS.glob("*.py") if '__name__ == "__main__"' in p.read_text())
#: a seed of the current held-out set, which the development scripts refuse
HELD_OUT = HELDOUT_SEEDS + 1


def _parses_arguments(tree):
    """Whether the module imports argparse or the studies' shared command line (``study_cli``)."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Import) and any(a.name in ("argparse", "study_cli") for a in node.names):
            return True
        if isinstance(node, ast.ImportFrom) and node.module in ("argparse", "study_cli"):
            return True
    return False


def _indexes_argv(tree):
    """Whether the module reads ``sys.argv[...]`` itself (a missing argument is then an IndexError)."""
    return any(isinstance(node, ast.Subscript) and isinstance(node.value, ast.Attribute) and node.value.attr == "argv"
               for node in ast.walk(tree))


def _script_module(name):
    """``analysis/NAME`` loaded as a module (its ``__main__`` block not run), with ``analysis/`` on the path while
    it imports, as when run from there (its ``study_cli``; the tests that use it passed only after another test
    had left ``analysis/`` on the path)."""
    spec = importlib.util.spec_from_file_location(Path(name).stem, ANALYSIS / name)
    module = importlib.util.module_from_spec(spec)
    sys.path.insert(0, str(ANALYSIS))
    try:
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(ANALYSIS))
    return module


def _in_process(script, args, monkeypatch, capsys, cwd):
    """``python analysis/SCRIPT ARGS`` run in this process, with no dataset generated, diagnosed or replayed: the
    exit status, standard output and standard error. (A subprocess spent 2 s importing SciPy and Drake for each
    refusal; ``test_gap_benchmark_rows_files_are_checked_and_a_resumed_shard_is_scored_once`` keeps the
    command-line path.)"""
    import drakecreep
    from drakecreep.gap import benchmark, drake_replay

    # every module of the package imported before the patches, so none binds a patched name for good
    for info in pkgutil.walk_packages(drakecreep.__path__, "drakecreep."):
        if not info.name.endswith("__main__"):
            importlib.import_module(info.name)

    def work(*args, **kwargs):
        raise AssertionError(f"{script} started the work before refusing {args!r}")

    for module, name in ((benchmark, "generate_dataset"), (benchmark, "evaluate"), (benchmark, "run_benchmark"),
                         (drake_replay, "replay_drakecreep")):
        monkeypatch.setattr(module, name, work)
    monkeypatch.syspath_prepend(str(ANALYSIS))
    monkeypatch.chdir(cwd)
    monkeypatch.setattr(sys, "argv", [str(ANALYSIS / script), *args])
    module = _script_module(script)
    capsys.readouterr()
    try:
        code = module.main()
    except SystemExit as exc:
        code = exc.code
    out = capsys.readouterr()
    return code, out.out, out.err


def test_there_are_scripts():
    assert len(SCRIPTS) > 30


@pytest.mark.parametrize("path", SCRIPTS, ids=lambda p: p.name)
def test_each_script_parses_its_arguments(path):
    tree = ast.parse(path.read_text())
    assert _parses_arguments(tree), f"{path.name}: --help would run the job (no argparse)"
    assert not _indexes_argv(tree), f"{path.name}: reads sys.argv[...] itself"


def _bench(*args, cwd):
    env = dict(os.environ, PYTHONPATH=str(ANALYSIS.parent))
    return subprocess.run([sys.executable, str(ANALYSIS / "bench_gap_benchmark.py"), *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=300)


def test_gap_benchmark_rows_files_are_checked_and_a_resumed_shard_is_scored_once(tmp_path):
    missing = _bench("--resume", str(tmp_path / "none.json"), cwd=tmp_path)
    assert missing.returncode == 2 and "Traceback" not in missing.stderr
    assert missing.stderr.strip().splitlines()[-1].endswith(
        "error: --resume: cannot read '%s' (No such file or directory); allowed: a rows file written by --json"
        % (tmp_path / "none.json"))
    (tmp_path / "bad.json").write_text('{"datasets": [1]}')
    bad = _bench("--score", str(tmp_path / "bad.json"), cwd=tmp_path)
    assert bad.returncode == 2 and "--score" in bad.stderr and "Traceback" not in bad.stderr
    # rows drawn with another --mass-spread are not resumed (their params files declare other masses)
    (tmp_path / "spread.json").write_text(json.dumps({"seeds": "heldout", "seed": HELDOUT_SEEDS, "mass_spread": 0.15,
                                                      "datasets": [{"seed": HELDOUT_SEEDS + 3}]}))
    spread = _bench("--kinds", "drakecreep", "--resume", str(tmp_path / "spread.json"), cwd=tmp_path)
    assert spread.returncode == 2 and spread.stderr.strip().splitlines()[-1].endswith(
        "was run with --mass-spread 0.15; allowed: the same --mass-spread (got 0.0)")
    rows = ANALYSIS / "gap_benchmark_drakecreep_heldout3.json"
    data = json.loads(rows.read_text())
    (tmp_path / "a.json").write_text(json.dumps(dict(data, datasets=data["datasets"][:2])))
    (tmp_path / "b.json").write_text(json.dumps(data))  # resumed from a.json: it repeats a.json's rows
    once = _bench("--score", str(rows), cwd=tmp_path)
    scored = _bench("--score", str(tmp_path / "a.json"), str(tmp_path / "b.json"), cwd=tmp_path)
    assert once.returncode == 0 and scored.returncode == 0, scored.stderr
    assert scored.stdout == once.stdout
    assert f"(n={sum(r['category'] == 'null' for r in data['datasets'])})" in once.stdout


@pytest.mark.parametrize("script, args, field", [
    ("bench_diagnose.py", ("--workers", "0", "--paper-rig"), "--workers: got 0"),
    ("bench_diagnose.py", ("--skip-emps",), "--skip-emps: got it without --paper-rig"),
    ("bench_diagnose.py", ("--uncertain", "table.mass"), "--uncertain: got 'table.mass' without --paper-rig"),
    ("bench_diagnose.py", ("--paper-rig", "--uncertain", "table.bogus"), "uncertain: got 'table.bogus'"),
    ("bench_replay_drakecreep.py", ("--repeat", "0"), "--repeat: got 0"),
    ("drive_named_candidates.py", ("cogging",), "NAME: got 'cogging'; allowed: one of backlash"),
    ("drive_named_candidates.py", ("--seed", "-3"), "--seed: got -3; allowed: an integer >= 0"),
    ("bench_gap_benchmark.py", ("--uncertain", "loads.constant_force"), "uncertain: got 'loads.constant_force'; "
                                                                      "allowed: only with kinds drakecreep alone"),
    ("bench_gap_benchmark.py", ("--kinds", "drakecreep", "--effects", "lead_error,drive_gain"),
     "effects: got 'drive_gain'"),
    ("bench_gap_benchmark.py", ("--skip-seeds", "104000"), "--skip-seeds: got (104000,) with --seeds heldout"),
    ("bench_gap_benchmark.py", ("--mass-spread", "0.15"), "--mass-spread: got 0.15; allowed: 0 unless kinds"),
    ("bench_gap_benchmark.py", ("--kinds", "drakecreep", "--mass-spread", "0.7"), "--mass-spread: got 0.7"),
    ("bench_gap_benchmark.py", ("--seeds", "dev", "--skip-seeds", "114003-114000"), "'114003-114000': seeds >= 0"),
    ("bench_gap_benchmark.py", ("--kinds", "drakecreep", "--checkpoints", "/dev/null/steps"),
     "--checkpoints: got '/dev/null/steps'; allowed: a folder"),
])
def test_diagnosis_benches_refuse_bad_options_before_any_work(tmp_path, monkeypatch, capsys, script, args, field):
    code, out, err = _in_process(script, args, monkeypatch, capsys, tmp_path)
    assert code == 2 and out == "" and field in err.strip().splitlines()[-1]


def _drive_row(seed, category, expected, snr, nominal, ranking, claimed, oscillation=None):
    return {"seed": seed, "kind": "drakecreep", "category": category, "expected": expected, "snr": snr,
            "withheld": [] if category == "null" else [expected], "claimed": claimed, "oscillation": oscillation,
            "test_force_nominal_runs": nominal, "ranking": ranking, "replay_null": 0.01}


def _ranked(effect, runs, train_gain=0.5):
    return {"effect": effect, "train_gain": train_gain, "test_force_runs": runs}


def test_drive_claim_statistics_recounts_the_first_claims(tmp_path):
    """The recount of drakecreep-kind rows: a lead error whose five held-out runs all shrink by very different
    amounts fails the Student bars on points and on log ratios but passes the sign-flip test; a null's candidate
    that helps two runs of five is claimed by none; a row without per-run errors (written before session 55) is
    skipped."""
    dcs = _script_module("drive_claim_statistics.py")
    nominal = [10.0, 12.0, 30.0, 11.0, 40.0]
    lead = _ranked("lead_error", [9.9, 11.5, 12.0, 10.8, 14.0])  # gains 0.1-26 points, all positive
    noise = _ranked("force_ripple", [9.0, 11.0, 30.5, 11.5, 40.2])
    rows = [_drive_row(1, "library", "lead_error", 9.0, nominal, [lead, noise], []),
            _drive_row(2, "null", None, 0.0, nominal, [noise], []),
            dict(_drive_row(3, "null", None, 0.0, None, [], []), test_force_nominal_runs=None)]
    claims = dcs.first_claims(rows[0])
    # (the log ratios, 0.01-1.05, differ as much as the points: a log-ratio bar does not pass it either)
    assert claims == {"points_t": None, "sign_flip": "lead_error", "t_or_sign_flip": "lead_error",
                      "log_ratio_t": None, "points_t_chi2": "n/a", "pooled_chi2": "n/a",  # rows before 752729f
                      "t_or_pooled_20": "lead_error",  # its pooled shrink, 76 %, is 76 run-to-run nulls
                      "product": None, "product_share_20": None}  # the row's own verdicts: none passed
    assert set(dcs.first_claims(rows[1]).values()) == {None}
    assert set(dcs.first_claims(dict(rows[0], replay_null=None)).values()) == {None}  # as the product: no null
    table, scores = dcs.recount(rows)
    assert [r["seed"] for r, _ in table] == [1, 2]
    assert scores["t_or_sign_flip"] == {"right": 1, "library": 1, "null_claims": 0, "nulls": 1, "wrong": 0}
    assert scores["points_t"]["right"] == 0
    (tmp_path / "rows.json").write_text(json.dumps({"datasets": rows}))
    out = subprocess.run([sys.executable, str(ANALYSIS / "drive_claim_statistics.py"), str(tmp_path / "rows.json")],
                         capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(ANALYSIS.parent)))
    assert out.returncode == 0 and "t_or_sign_flip   top-1 at SNR >= 3: 1 / 1" in out.stdout, out.stdout + out.stderr
    (tmp_path / "bad.json").write_text("[1, 2]")
    assert "n/a" in out.stdout and "pooled_chi2      top-1 at SNR >= 3: 0 / 0" in out.stdout
    bad = subprocess.run([sys.executable, str(ANALYSIS / "drive_claim_statistics.py"), str(tmp_path / "bad.json")],
                         capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(ANALYSIS.parent)))
    assert bad.returncode == 2 and "rows: got" in bad.stderr and "Traceback" not in bad.stderr


def test_drive_claim_statistics_weighs_the_training_gain(tmp_path):
    """Study 3br's two rules on rows that carry the training fit's SSE and variance: development dataset 104011's
    case, a lead error of very different per-run gains (Student bar failed) above a flat curve of tiny, alike gains
    (Student bar passed, training gain 0.2 %). ``points_t`` claims the flat curve; with the training chi-square
    test it is out (0.15 against the 5 % quantile of two degrees of freedom, 5.99), and the pooled test alone
    claims the lead error (50 against 11.07 for its five fields)."""
    dcs = _script_module("drive_claim_statistics.py")
    nominal = [10.0, 12.0, 30.0, 11.0, 40.0]
    lead = dict(_ranked("lead_error", [9.9, 11.5, 12.0, 10.8, 14.0]),
                values={"disturbance.lead_error_amplitude": 2e-6, "disturbance.lead_error_period": 4e-4,
                        "disturbance.lead_error_phase": 0.3})
    flat = dict(_ranked("stribeck", [e - 0.02 for e in nominal], train_gain=0.0015),
                values={"friction.static_ratio": 1.014, "friction.stribeck_velocity": 8e-4, "friction.law": "lugre",
                        "table.seal_force": 4.7})
    row = dict(_drive_row(4, "library", "lead_error", 4.8, nominal, [lead, flat], ["stribeck"]), replay_null=0.001,
               train_sse=100.0, train_variance=1.0, uncertain=["table.seal_force"])
    assert dcs.training_chi2(row, flat) == (pytest.approx(0.15), 2)  # the refitted uncertain field is no new one
    assert dcs.training_chi2(row, lead) == (pytest.approx(50.0), 5)  # fundamental and second harmonic
    from drakecreep.gap.drive_fit import EFFECTS

    assert set(dcs.CANDIDATE_FIELDS) == set(EFFECTS)  # every candidate has its degrees of freedom
    claims = dcs.first_claims(row)
    assert (claims["points_t"], claims["points_t_chi2"], claims["pooled_chi2"]) == ("stribeck", None, "lead_error")
    null = dict(_drive_row(5, "null", None, 0.0, nominal, [flat], []), replay_null=0.001, train_sse=100.0,
                train_variance=1.0, uncertain=["table.seal_force"])
    _, scores = dcs.recount([row, null])
    assert scores["pooled_chi2"] == {"right": 1, "library": 1, "null_claims": 0, "nulls": 1, "wrong": 0}
    assert scores["points_t"] == {"right": 0, "library": 1, "null_claims": 1, "nulls": 1, "wrong": 2}


def test_drive_claim_statistics_lets_a_large_pooled_shrink_stand_for_the_student_bar():
    """Study 3bs's rule: a candidate that fails the Student bar on its per-run gains is claimed when its pooled
    held-out shrink is above 20 run-to-run nulls, and not when it is above the null but below 20 of them."""
    dcs = _script_module("drive_claim_statistics.py")
    nominal = [10.0, 12.0, 30.0, 11.0, 40.0]
    lead = _ranked("lead_error", [9.9, 11.5, 12.0, 10.8, 14.0])  # shrink 76 % of the pooled energy
    row = _drive_row(1, "library", "lead_error", 5.0, nominal, [lead], [])
    assert dcs.first_claims(row)["points_t"] is None
    assert dcs.first_claims(row)["t_or_pooled_20"] == "lead_error"  # null 1 %: 76 nulls
    assert dcs.first_claims(dict(row, replay_null=0.05))["t_or_pooled_20"] is None  # 15 nulls: not enough
    # a null's candidate that helps four runs a little, unevenly: shrink 2.0 %, two nulls, Student bar failed
    small = _ranked("force_ripple", [9.9, 11.9, 29.0, 10.9, 40.1], train_gain=0.04)
    null = _drive_row(2, "null", None, 0.0, nominal, [small], [])
    assert dcs.first_claims(null)["points_t"] is None and dcs.first_claims(null)["t_or_pooled_20"] is None
    _, scores = dcs.recount([row, null])
    assert scores["t_or_pooled_20"] == {"right": 1, "library": 1, "null_claims": 0, "nulls": 1, "wrong": 0}


def test_drive_claim_statistics_floors_the_product_verdicts_on_the_training_gain(tmp_path):
    """Study 3cw's rule: the row's own verdicts in ranking order, among candidates whose training gain is at least
    a fifth. A stand-in delay that passed with 0.47 % of training gain (run 15's 109101000) is withheld and the
    true effect ranked below it claimed; a spectrum claim on an oscillating loop is left as the row made it; an
    exact repeat of a row (a resumed shard's) counts once, another row of the same seed does not."""
    dcs = _script_module("drive_claim_statistics.py")
    nominal = [21.3, 42.6, 35.7, 47.4, 47.4]
    delay = dict(_ranked("control_delay", [21.35, 42.04, 35.22, 45.90, 46.58], train_gain=0.0047), passes=True)
    ripple = dict(_ranked("force_ripple", [20.0, 40.0, 33.0, 44.0, 45.0], train_gain=0.25), passes=True)
    low = dict(_ranked("stribeck", [21.0, 42.0, 35.0, 46.0, 46.0], train_gain=0.19), passes=True)
    stand_in = dict(_drive_row(7, "out_of_library", None, 0.4, nominal, [delay], ["control_delay"]),
                    first_passing="control_delay", withheld=["asymmetric_friction"])
    claims = dcs.first_claims(stand_in)
    assert (claims["product"], claims["product_share_20"]) == ("control_delay", None)
    assert dcs.MIN_TRAIN_SHARE == 0.20
    ranked = _drive_row(8, "library", "force_ripple", 3.5, nominal, [delay, low, ripple], ["control_delay"])
    assert dcs.product_claim(ranked, dcs.MIN_TRAIN_SHARE) == "force_ripple"  # 0.19 is under the floor too
    assert dcs.product_claim(ranked, 0.19) == "stribeck"
    spectrum = _drive_row(9, "library", "control_delay", 300.0, nominal, [], ["control_delay"],
                          oscillation={"freq_Hz": 207.0})
    assert dcs.first_claims(spectrum)["product_share_20"] == "control_delay"
    other = dict(stand_in, withheld=["load_friction"])  # another effect drawn on the same seed (3cr)
    (tmp_path / "a.json").write_text(json.dumps({"datasets": [stand_in, ranked]}))
    (tmp_path / "b.json").write_text(json.dumps({"datasets": [stand_in, other, spectrum]}))
    out = subprocess.run([sys.executable, str(ANALYSIS / "drive_claim_statistics.py"), str(tmp_path / "a.json"),
                          str(tmp_path / "b.json")], capture_output=True, text=True,
                         env=dict(os.environ, PYTHONPATH=str(ANALYSIS.parent)))
    assert out.returncode == 0, out.stderr
    assert "product          top-1 at SNR >= 3: 1 / 2; claims on nulls: 0 / 0; wrong first claims: 3" in out.stdout
    assert "product_share_20 top-1 at SNR >= 3: 2 / 2; claims on nulls: 0 / 0; wrong first claims: 0" in out.stdout


def _spectral_row(seed, e0, e1, osc, same, passes, withheld=("control_delay",), keep_runs=True):
    dec = [e0[i] - e1[i] for i in osc]
    sp = {"nominal_nepers": e0, "delay_nepers": e1, "same_frequency": same, "spurious": 0, "passes": passes,
          "oscillating": len(osc), "gain": float(np.mean(dec)), "of": len(e0)}
    if keep_runs:
        sp["oscillating_runs"] = list(osc)
    return {"seed": seed, "kind": "drakecreep", "withheld": list(withheld), "replay_null": 0.01,
            "oscillation": {"runs": 3, "of": 4, "spectral": sp}}


def test_spectral_claim_recount_reads_the_detectors_criterion_run_by_run(tmp_path):
    """Study 3cz's recount: run 14's 107106006 (3 of 5 held-out runs oscillating, decreases 7.47, 1.64 and 7.05 Np)
    fails the product's Student bar and passes the detector's criterion (each of the three within ln 10 of the
    measurement, the fitted model beyond it); 105106022's (one of two reproduced) fails both; a row without the
    oscillating runs has them inferred from the largest nominal errors and its gain, or reads n/a."""
    rec = _script_module("spectral_claim_recount.py")
    e0, e1 = [0.13, 0.61, 7.59, 3.79, 7.08], [0.21, 0.43, 0.12, 2.15, 0.03]
    row = _spectral_row(107106006, e0, e1, [2, 3, 4], 2, False)
    osc = rec.oscillating_runs(row["oscillation"]["spectral"])
    assert osc == [2, 3, 4]
    assert (rec.spectral_passes("student", row["oscillation"]["spectral"], osc),
            rec.spectral_passes("detector", row["oscillation"]["spectral"], osc)) == (False, True)
    two = _spectral_row(105106022, [5.53, 8.01, 1.54, 2.41, 1.52], [2.62, 0.15, 1.29, 1.05, 1.18], [0, 1], 2,
                        False, keep_runs=False)
    assert rec.oscillating_runs(two["oscillation"]["spectral"]) == [0, 1]  # inferred: the two largest, its gain
    (_, v1, _), (_, v2, _) = rec.recount([row, two])
    assert v1 == {"student": False, "detector": True} and v2 == {"student": False, "detector": False}
    assert rec.recount([dict(row, replay_null=None)])[0][1]["detector"] is False  # no null, no claim
    odd = _spectral_row(1, e0, e1, [2, 3, 4], 2, False, keep_runs=False)
    odd["oscillation"]["spectral"]["gain"] = 9.0  # no subset of the largest errors gives it
    assert rec.recount([odd])[0][1] == {"student": "n/a", "detector": "n/a"}
    (tmp_path / "rows.json").write_text(json.dumps({"datasets": [row, two, row]}))
    out = subprocess.run([sys.executable, str(ANALYSIS / "spectral_claim_recount.py"), str(tmp_path / "rows.json")],
                         capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(ANALYSIS.parent)))
    assert out.returncode == 0, out.stderr
    assert "detector  passes 1 of 2 rows (1 of 2 with a withheld delay)" in out.stdout  # the repeat counts once
    bad = subprocess.run([sys.executable, str(ANALYSIS / "spectral_claim_recount.py"), str(tmp_path / "nope.json")],
                         capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(ANALYSIS.parent)))
    assert bad.returncode == 2 and "rows: got" in bad.stderr and "Traceback" not in bad.stderr


def test_oscillation_share_draws_one_effect_on_consecutive_seeds_of_one_axis():
    """3cy's probe: ``--effect`` draws that withheld effect alone on seeds SEED to SEED+N-1, ``--axis`` fixes the
    axis; without them every effect and the nulls on their seed blocks, the axes alternating."""
    osc = _script_module("oscillation_share.py")
    assert osc.specs(9000, 3, "drakecreep", "control_delay", "flexible") == [
        (9000 + j, ("control_delay",), "drakecreep", "flexible") for j in range(3)]
    every = osc.specs(3000, 2, "drakecreep")
    assert len(every) == 2 * (len(osc.T.WITHHELD) + 1) and {s[3] for s in every} == {"flexible", "rigid"}
    assert (3000 + 99 * 1000 + 1, (), "drakecreep", "rigid") in every


def test_backfill_writes_the_training_fit_only_where_it_reproduces_the_row(monkeypatch):
    """Study 3br's backfill on a small test-rig dataset standing in for a regenerated benchmark one: the nominal
    fit rerun gives the row's held-out errors, so the SSE and variance are written (and give the training
    chi-square of a recount); a row whose nominal errors differ by more than the tolerance is left as it was."""
    from types import SimpleNamespace

    from drakecreep.gap.drake_replay import quick_replay_params, simulated_runs
    from drakecreep.gap.drive_fit import _errors_of, _Replayer, fit_drive
    from drakecreep.params import preset

    rig = quick_replay_params(preset("paper"))
    runs = simulated_runs(rig, (0.02, 0.03, 0.025, 0.035), declared=rig, n=400, noise=2.0, seed=5)
    ds = SimpleNamespace(train=runs[:2], test=runs[2:])
    btf = _script_module("backfill_training_fit.py")
    monkeypatch.setattr(btf, "generate_dataset", lambda seed, **kw: ds)
    uncertain = ["table.seal_force"]
    params = fit_drive(ds.train, rig, uncertain, _Replayer(0), max_nfev=20)[0]
    nominal = [e["force"] for e in _errors_of(ds.test, _Replayer(0)(ds.test, params)).values()]
    row = {"seed": 1, "withheld": [], "kind": "drakecreep", "axis": "rigid", "uncertain": uncertain,
           "test_force_nominal_runs": nominal}
    lines = []
    new, diff = btf.backfill(row, say=lines.append)
    assert diff < 1e-9 and new["train_sse"] > 0 and new["train_variance"] > 0 and new["backfilled"]["replays"] > 0
    assert "train_sse" not in row  # a copy
    off = dict(row, test_force_nominal_runs=[e + 0.01 for e in nominal])
    same, diff = btf.backfill(off, say=lines.append)
    assert same is off and diff == pytest.approx(0.01) and "not reproduced" in lines[-1]


@pytest.mark.parametrize("args, field", [
    (("--out", "x.json", "--tolerance", "0"), "--tolerance: got 0.0"),
    (("--out", "x.json"), "rows: got"),  # held-out rows: refused
])
def test_backfill_refuses_bad_options_and_held_out_rows(tmp_path, monkeypatch, capsys, args, field):
    rows = ANALYSIS / "gap_benchmark_drakecreep_heldout3.json"
    code, _, err = _in_process("backfill_training_fit.py", (str(rows), *args), monkeypatch, capsys, tmp_path)
    assert code == 2 and field in err.strip().splitlines()[-1]
    assert not (tmp_path / "x.json").exists()


def test_drive_true_shrink_counts_only_rows_it_reproduces(tmp_path, monkeypatch, capsys):
    """The true effect's audit shrink of an older drakecreep-kind row: the dataset regenerated from the row's seed
    gives the row's own audit energy again (its claim's values, then the final refit's, a refitted amplitude
    among them), and the true model is the fitted uncertain fields with the truth's effect (not the claim's
    refitted amplitude); a row whose energy is not reproduced is flagged; bad options are refused before any work."""
    from drakecreep.gap.benchmark import DEV_SEEDS, generate_dataset, true_drive_values
    from drakecreep.gap.drive_fit import _with

    monkeypatch.syspath_prepend(str(ANALYSIS))  # its study_cli, as when run from analysis/
    dts = _script_module("drive_true_shrink.py")
    seed, withheld = DEV_SEEDS + 7, ["lead_error"]
    ds = generate_dataset(seed, withheld=tuple(withheld), kind="drakecreep", axis="rigid", n_samples=600)
    declared = ds.train[0].meta.params
    uncertain = {"table.seal_force": 1.1 * declared.table.seal_force}  # as a nominal fit would give
    ripple = {"disturbance.force_ripple": 1.0, "disturbance.ripple_frequency": 7.0, "disturbance.ripple_phase": 0.3}
    fitted = dict(uncertain, **{"disturbance.force_ripple": 2.0})  # the final refit moved the claim's amplitude
    nominal = dts._energy(ds.audit, _with(declared, uncertain))
    claimed = dts._energy(ds.audit, _with(_with(declared, ripple), fitted))
    true = dts._energy(ds.audit, _with(_with(declared, uncertain), true_drive_values(ds.truth)))
    row = {"seed": seed, "withheld": withheld, "kind": "drakecreep", "axis": "rigid", "snr": 4.0,
           "claimed": ["force_ripple"], "expected": "lead_error", "audit_shrink": 1 - claimed / nominal,
           "uncertain": ["table.seal_force"],
           "claimed_model": {"fitted": fitted, "effects": {"force_ripple": ripple}},
           "audit": {"nominal": {"energy": nominal}, "claimed": {"energy": claimed}}}
    r = dts.true_shrink(row, n_samples=600)
    assert r["reproduced"] and r["check"] < 1e-9 and r["base"] == "refit"
    assert r["true_energy"] == pytest.approx(true, rel=1e-12) and r["true_shrink"] == pytest.approx(1 - true / nominal)
    assert r["relative"] == (None if r["true_shrink"] <= 0 else pytest.approx(row["audit_shrink"] / r["true_shrink"]))
    off = dict(row, audit={"nominal": {"energy": nominal}, "claimed": {"energy": 1.01 * claimed}})
    r = dts.true_shrink(off, n_samples=600)
    assert not r["reproduced"] and r["check"] == pytest.approx(1 - 1 / 1.01, abs=1e-9)
    rows = ANALYSIS / "gap_benchmark_drakecreep_heldout3.json"
    for args, field in ((("--tolerance", "0"), "--tolerance: got 0.0"), (("--samples", "10"), "--samples: got 10"),
                        (("--json", str(tmp_path)), "--json: got"), ((), "rows: cannot read")):
        argv = [str(rows), *args] if args else [str(tmp_path / "none.json")]
        code, _, err = _in_process("drive_true_shrink.py", argv, monkeypatch, capsys, tmp_path)
        assert code == 2 and field in err.strip().splitlines()[-1]


def test_the_shipped_drive_example_is_what_its_script_makes():
    """``drakecreep/data/examples/drive_lead_error.csv`` (runs of the project's controller) is what
    ``analysis/make_drive_example.py`` writes: its runs, sample by sample, and its metadata's params file, the test
    rig without the lead error the runs carry."""
    from drakecreep.data import example_path
    from drakecreep.gap.measured import load_measured

    mde = _script_module("make_drive_example.py")
    rig, runs = mde.example_runs()
    shipped = load_measured(example_path("drive_lead_error.csv"))
    assert [r.label for r in shipped.runs] == [r.label for r in runs] and len(runs) == len(mde.SPEEDS)
    for got, want in zip(shipped.runs, runs):
        np.testing.assert_allclose(got.x_motor, want.x_motor, rtol=0, atol=1e-12)
        np.testing.assert_allclose(got.u, want.u, rtol=1e-12, atol=1e-9)
    assert shipped.meta.controller.kind == "drakecreep" and shipped.meta.params == rig
    assert shipped.meta.params.disturbance.lead_error_amplitude == 0.0 and mde.LEAD_ERROR > 0


def _lowpass_row(seed, category, expected, nominal, nominal_low, ranking, refits_low, oscillation=None):
    row = _drive_row(seed, category, expected, 5.0 if expected else 0.0, nominal, ranking, [], oscillation)
    row.update(axis="flexible", test_force_lowpass_nominal_runs=nominal_low, null_test_force_lowpass_runs=refits_low,
               first_passing=next((c["effect"] for c in ranking if c["passes"]), None))
    return row


def _low(effect, runs, low, passes=False, gain=0.0, transmission=None):
    return dict(_ranked(effect, runs), test_force_lowpass_runs=low, passes=passes, gain=gain,
                transmission=transmission)


def test_lowpass_claim_recount_decides_on_the_force_below_100_hz(tmp_path):
    """The recount of the first claim on ``force_lowpass`` (docs 3ce): a ripple whose whole force errors hardly
    move (the count ripple drawn anew; the row's own verdict is no claim) but whose errors below 100 Hz halve on
    every run is claimed there; a null's candidate moving below 100 Hz within the refits' spread is not; a lead
    error decided on the transmission keeps its verdict; rows without the fields are refused in one line."""
    sys.path.insert(0, str(ANALYSIS))
    try:
        lcr = _script_module("lowpass_claim_recount.py")
    finally:
        sys.path.remove(str(ANALYSIS))
    nominal, low = [30.0, 32.0, 35.0, 31.0, 33.0], [12.0, 14.0, 15.0, 13.0, 12.5]
    refits = [[12.1, 14.0, 15.1, 12.9, 12.5], [11.9, 14.1, 14.9, 13.0, 12.6]]  # a null of about 1.5 %
    ripple = _low("force_ripple", [29.5, 32.5, 34.0, 31.5, 32.0], [6.0, 7.5, 7.0, 6.5, 6.0], gain=0.3)
    row = _lowpass_row(1, "library", "force_ripple", nominal, low, [ripple], refits)
    x = lcr.recount_row(row)
    assert x["first_passing"] is None and x["first_passing_lowpass"] == "force_ripple"
    assert x["null_lowpass"] == pytest.approx(max(abs(1 - sum(v * v for v in r) / sum(v * v for v in low))
                                                  for r in refits))
    drift = _low("law_coulomb", [29.0, 33.0, 34.0, 32.0, 32.5], [11.95, 14.05, 14.95, 13.0, 12.45], gain=0.2)
    null = lcr.recount_row(_lowpass_row(2, "null", None, nominal, low, [drift], refits))
    assert null["first_passing_lowpass"] is None
    lead = _low("lead_error", nominal, low, passes=True, gain=0.0, transmission={"passes": True})
    y = lcr.recount_row(_lowpass_row(3, "library", "lead_error", nominal, low, [lead], refits))
    assert y["first_passing_lowpass"] == "lead_error" and y["candidates"][0]["kept"]
    assert lcr.recount_row(dict(row, test_force_lowpass_nominal_runs=None)) is None
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ANALYSIS), str(ANALYSIS.parent)]))
    (tmp_path / "rows.json").write_text(json.dumps({"datasets": [row]}))
    out = subprocess.run([sys.executable, str(ANALYSIS / "lowpass_claim_recount.py"), str(tmp_path / "rows.json")],
                         capture_output=True, text=True, env=env)
    assert out.returncode == 0 and "below 100 Hz   : top-1 (first claim) 1 / 1" in out.stdout, out.stdout + out.stderr
    (tmp_path / "old.json").write_text(json.dumps({"datasets": [dict(row, test_force_lowpass_nominal_runs=None)]}))
    bad = subprocess.run([sys.executable, str(ANALYSIS / "lowpass_claim_recount.py"), str(tmp_path / "old.json")],
                         capture_output=True, text=True, env=env)
    assert bad.returncode == 2 and "rows: got no drakecreep row" in bad.stderr and "Traceback" not in bad.stderr


def _refused_in_one_line(script, cases, monkeypatch, capsys, cwd):
    """Each ``(args, says)`` of ``cases`` run as ``analysis/SCRIPT`` exits 2 before any work, ``says`` in its last
    line."""
    for args, says in cases:
        code, _, err = _in_process(script, args, monkeypatch, capsys, cwd)
        assert code == 2, (args, err)
        assert says in err.strip().splitlines()[-1]


def test_diagnose_dataset_refuses_bad_datasets_and_held_out_seeds_in_one_line(tmp_path, monkeypatch, capsys):
    """``analysis/diagnose_dataset.py``: a malformed dataset, a seed of the current held-out set and an unknown kind
    each exit 2 with one line before any dataset is generated; the summary line carries the verdict and audit."""
    whole, partial = tmp_path / "whole.json", tmp_path / "partial.json"
    whole.write_text(json.dumps({"complete": True, "datasets": [{"seed": HELD_OUT}]}))
    partial.write_text(json.dumps({"complete": False, "datasets": [{"seed": HELD_OUT + 1}]}))
    cases = ((["9014:nothing:flexible", "--kind", "drakecreep"], "nothing"),
             ([f"{HELD_OUT}:null:rigid", "--kind", "drakecreep"], str(HELD_OUT)),
             ([f"{HELD_OUT + 1}:null:rigid", "--kind", "drakecreep", "--spent", str(whole)], str(HELD_OUT + 1)),
             ([f"{HELD_OUT + 1}:null:rigid", "--kind", "drakecreep", "--spent", str(partial)], "complete"),
             ([f"{HELD_OUT}:null:rigid", "--kind", "drakecreep", "--spent", str(tmp_path / "no.json")], "--spent"),
             (["9014:null:rigid", "--kind", "pi"], "--kind"),
             (["9014:null:rigid", "--kind", "drakecreep", "--json", "/proc/x.json"], "--json"),
             (["9014:null:rigid", "--kind", "drakecreep", "--effects", "control_delay,drive_gain"], "--effects"),
             (["9014:null:rigid", "--kind", "drakecreep", "--effects", ","], "--effects"),
             (["9014:null:rigid", "--kind", "p_p_cascade", "--effects", "control_delay"], "--effects"))
    _refused_in_one_line("diagnose_dataset.py", cases, monkeypatch, capsys, tmp_path)
    # a seed of a complete run's rows is let through: the dataset is generated (here a failure, kept going past)
    code, out, _ = _in_process("diagnose_dataset.py", [f"{HELD_OUT}:null:rigid", "--kind", "drakecreep", "--spent",
                                                       str(whole)], monkeypatch, capsys, tmp_path)
    assert code == 1 and "started the work" in out
    dd = _script_module("diagnose_dataset.py")
    row = {"seed": 1205, "withheld": ["lead_error"], "axis": "flexible", "snr": 24.2, "claimed": ["lead_error"],
           "first_passing": "lead_error", "audit_shrink": 0.9695, "true_shrink": 0.9695, "worse": False,
           "audit": {"nominal": {"force_rms": 29.88, "force_lowpass_rms": 26.64},
                     "claimed": {"force_rms": 5.21, "force_lowpass_rms": 3.55}, "true": None}}
    line = dd.summary(row)
    assert "claimed ['lead_error']" in line and "29.88 % (< 100 Hz 26.64)" in line and "true -" in line
    assert "shrink 97.0 %" in line and "worse False" in line


def test_diagnose_dataset_keeps_going_past_a_failing_dataset(tmp_path, monkeypatch, capsys):
    """A dataset whose diagnosis fails (a drawn drive saturation the run check refused as a wrong unit, docs 3cr)
    is one line and a ``failed`` entry; the next dataset is still diagnosed and kept; the exit status is 1."""
    from drakecreep.errors import InputError
    from drakecreep.gap import benchmark

    def evaluate(ds, effects=None):
        if ds == 1:
            raise InputError("x_motor (run run0)", "an inverse-dynamics mass of 935.3 kg", "within a factor of 10")
        return {"seed": 2, "withheld": ["null"], "axis": "rigid", "claimed": [], "effects": effects}

    monkeypatch.setattr(benchmark, "generate_dataset", lambda seed, **kw: seed)
    monkeypatch.setattr(benchmark, "evaluate", evaluate)
    monkeypatch.setattr(sys, "argv", ["diagnose_dataset.py", "1:drive_saturation:flexible", "2:null:rigid", "--kind",
                                      "drakecreep", "--effects", "control_delay", "--json", str(tmp_path / "o.json")])
    monkeypatch.syspath_prepend(str(ANALYSIS))
    assert _script_module("diagnose_dataset.py").main() == 1
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("1 drive_saturation flexible: failed (InputError: x_motor (run run0)")
    assert out[1].startswith("2 null rigid SNR 0.0: claimed nothing")
    kept = json.loads((tmp_path / "o.json").read_text())
    assert kept["effects"] == ["control_delay"] and [r["seed"] for r in kept["datasets"]] == [2]
    assert kept["datasets"][0]["effects"] == ["control_delay"]
    assert kept["failed"][0]["seed"] == 1 and "935.3 kg" in kept["failed"][0]["error"]


def test_declared_mass_study_refuses_bad_cases_and_held_out_seeds_in_one_line(tmp_path, monkeypatch, capsys):
    """``analysis/declared_mass_study.py``: a malformed case, an unknown effect, a factor out of range, a seed of the
    held-out set and an uncertain field it cannot fit (or given twice) each exit 2 with one line before any dataset
    is generated."""
    cases = ((["114000:null:flexible"], "SEED:WITHHELD:AXIS"), (["114000:nothing:flexible:0.85"], "nothing"),
             (["114000:null:flexible:x"], "factor"), (["114000:null:flexible:0"], "factor"),
             ([f"{HELD_OUT}:null:rigid:1.15"], str(HELD_OUT)),
             (["114000:null:flexible:0.85", "--uncertain", "table.bogus"], "table.bogus"),
             (["114000:null:flexible:0.85", "--uncertain", "table.mass,table.mass"], "given twice"),
             (["114000:null:flexible:1.5", "--field", "screw.lead"], "--field"))
    _refused_in_one_line("declared_mass_study.py", cases, monkeypatch, capsys, tmp_path)


def test_declared_field_study_scales_the_whole_axial_chain():
    """3cx's ``--field axial_chain``: the bearing's, the nut's and the shaft's stiffness all times the factor, so
    the two-mass model's axial stiffness is too (at any nut position), its damping and everything else kept; a
    single field is scaled alone."""
    from drakecreep.model.screw import axial_damping, axial_stiffness
    from drakecreep.params import params_to_dict, preset

    m = _script_module("declared_mass_study.py")
    p = preset()
    wrong, declared, true = m.declare(p, "axial_chain", 1.5)
    assert (true, declared) == (p.screw.bearing_stiffness, pytest.approx(1.5 * p.screw.bearing_stiffness))
    for x in (0.0, 0.2, 0.45):
        assert axial_stiffness(wrong.screw, wrong.nut, x) == pytest.approx(1.5 * axial_stiffness(p.screw, p.nut, x))
        assert axial_damping(wrong.screw, wrong.nut, x) == pytest.approx(axial_damping(p.screw, p.nut, x))
    changed = {k for k, v in params_to_dict(wrong)["screw"].items() if params_to_dict(p)["screw"][k] != v}
    assert changed == {"bearing_stiffness", "youngs_modulus"}
    inertia, declared, true = m.declare(p, "motor.rotor_inertia", 0.85)
    assert declared == pytest.approx(0.85 * true) and params_to_dict(inertia)["nut"] == params_to_dict(p)["nut"]


def test_idim_mass_spread_reads_the_rigid_body_mass_of_runs_made_with_the_params_file(tmp_path, monkeypatch, capsys):
    """``analysis/idim_mass_spread.py``: the shipped drive example, made by the project's diagram with its own params
    file, reads an inverse-dynamics mass within 20 % of that file's rigid-body mass on every run; a malformed
    dataset and a seed of the held-out set exit 2 with one line before any dataset is generated."""
    import types

    from drakecreep.data import example_path
    from drakecreep.gap.runs import load_runs

    cases = ((["114000:null"], "SEED:WITHHELD:AXIS"), ([f"{HELD_OUT}:null:rigid"], str(HELD_OUT)))
    _refused_in_one_line("idim_mass_spread.py", cases, monkeypatch, capsys, tmp_path)
    runs = load_runs(example_path("drive_lead_error.csv"), split=False)
    row = _script_module("idim_mass_spread.py").spread(
        types.SimpleNamespace(seed=0, axis="flexible", withheld=(), train=runs, test=(), audit=()))
    assert row["table_mass_kg"] == runs[0].meta.params.table.mass
    assert len(row["ratios"]) == len(runs)
    assert all(r is not None and 0.8 < r < 1.2 for r in row["ratios"]), row["ratios"]


def test_delay_pattern_study_refuses_bad_ticks_and_held_out_seeds_in_one_line(tmp_path, monkeypatch, capsys):
    """``analysis/delay_pattern_study.py``: a tick that is not a whole number, a negative one and a seed of the
    held-out set each exit 2 with one line before any dataset is generated; the band RMS of a pure sine at its
    frequency is its RMS, and next to nothing an octave away."""
    cases = ((["9014", "--ticks", "8,x"], "--ticks"), (["9014", "--ticks", "-1"], "--ticks"),
             ([str(HELD_OUT)], str(HELD_OUT)))
    _refused_in_one_line("delay_pattern_study.py", cases, monkeypatch, capsys, tmp_path)
    dps = _script_module("delay_pattern_study.py")
    t = np.arange(3000) * 1e-3
    x = 3.0 * math.sqrt(2.0) * np.sin(2 * math.pi * 150.0 * t)
    assert abs(dps.band_rms(x, 1e-3, 150.0) - 3.0) < 0.15
    assert dps.band_rms(x, 1e-3, 300.0) < 0.05


def test_delay_signature_counts_the_runs_that_agree_and_are_helped(tmp_path, monkeypatch, capsys):
    """``analysis/delay_signature.py``: each run's own best delay against the fitted one (agreement) and its SSE at
    the fitted delay against the declared one (helped); a row without the record says so; an unreadable rows file
    is one line and exit 2."""
    monkeypatch.syspath_prepend(str(ANALYSIS))
    ds = _script_module("delay_signature.py")
    search = {"declared": 1.0, "delays": [0.0, 1.0, 4.0, 8.0],
              "run_sse": [[5.0, 4.0, 3.0, 3.5], [5.0, 4.0, 4.5, 2.0], [5.0, 4.0, 4.2, 6.0]],
              "run_best": [4.0, 8.0, 1.0]}
    row = {"seed": 7, "withheld": ["drive_saturation"], "axis": "rigid", "snr": 1.2,
           "ranking": [{"effect": "force_ripple", "values": {}},
                       {"effect": "control_delay", "passes": True, "train_gain": 0.04, "search": search,
                        "values": {"controller.computation_delay": 4.0}}]}
    s = ds.signature(row)
    assert s["fitted"] == 4.0 and s["declared"] == 1.0 and s["passes"]
    assert s["run_gain"] == pytest.approx([0.25, -0.125, -0.05])
    assert s["agreement"] == pytest.approx(1 / 3) and s["helped"] == pytest.approx(1 / 3)
    assert "agreement 1/3, helped 1/3" in ds.line(row) and "runs' own best 4, 8, 1" in ds.line(row)
    bare = dict(row, ranking=[{"effect": "control_delay", "values": {}}])
    assert ds.signature(bare) is None and ds.line(bare).endswith("no delay search recorded")
    rows = tmp_path / "rows.json"
    rows.write_text(json.dumps({"datasets": [row, bare]}))
    code, out, _ = _in_process("delay_signature.py", [str(rows)], monkeypatch, capsys, tmp_path)
    assert code == 0 and len(out.splitlines()) == 2
    _refused_in_one_line("delay_signature.py", (([str(tmp_path / "no.json")], "ROWS.json"),), monkeypatch, capsys,
                         tmp_path)


def test_single_run_oscillation_study_refuses_bad_datasets_and_reads_the_on_off_pattern(tmp_path, monkeypatch, capsys):
    """``analysis/single_run_oscillation.py`` (docs 3db): a malformed dataset, a held-out seed, an unwritable rows
    file, a checkpoint folder that is a file and a --max-nfev out of range exit 2 in one line before any dataset is
    generated; its pattern reads which runs oscillate, and its rule asks for the exact on/off pattern with a held-out
    run oscillating."""
    (tmp_path / "file").write_text("")
    cases = ((["o.json", "9073:nothing:flexible"], "nothing"),
             (["o.json", f"{HELD_OUT}:control_delay:flexible"], str(HELD_OUT)),
             (["/proc/o.json", "9073:control_delay:flexible"], "OUT.json"),
             (["o.json", "9073:control_delay:flexible", "--checkpoints", str(tmp_path / "file")], "--checkpoints"),
             (["o.json", "9073:control_delay:flexible", "--max-nfev", "0"], "--max-nfev"))
    _refused_in_one_line("single_run_oscillation.py", cases, monkeypatch, capsys, tmp_path)
    study = _script_module("single_run_oscillation.py")
    dt, t = 1e-3, np.arange(1000) * 1e-3
    rng = np.random.default_rng(0)
    quiet = rng.normal(0.0, 1.0, t.size)
    at = lambda f: 30.0 * np.sin(2 * np.pi * f * t) + quiet  # noqa: E731
    got = study.pattern([at(200.0), quiet, at(200.0)], [at(205.0), at(200.0), at(300.0)], dt, fallback_hz=200.0)
    assert [g["measured"] for g in got] == [True, False, True]
    # within 15 % of the measured 200 Hz; on a quiet run at the fallback frequency; 300 Hz is not 200 Hz
    assert [g["model"] for g in got] == [True, True, False]
    assert abs(got[0]["measured_hz"] - 200.0) < 5.0 and abs(got[2]["model_hz"] - 300.0) < 5.0
    held = [{"measured": m, "model": s} for m, s in ((True, True), (False, False), (False, False))]
    assert study.rule([True, False], [True, False], held) == (True, "the on/off pattern of every run matches")
    assert not study.rule([True, False], [True, True], held)[0]
    assert not study.rule([True, False], [True, False], [dict(h, model=True) for h in held])[0]
    assert study.rule([True, False], [True, False], [dict(h, measured=False, model=False) for h in held]) == \
        (False, "no held-out run oscillates")
