"""An unstable delay seen on one training run: does the delay that reproduces it predict the held-out runs?
(docs/gap_benchmark.md 3db, a development study; the product is not changed by it).

When the truth's computation delay drives the axial mode unstable on only one of the four training runs, the
``drakecreep`` diagnosis judges the delay sample by sample (the claims are withheld only when two and half of the
training or held-out runs oscillate, :func:`drakecreep.gap.drive_fit.claims_withheld`), where an oscillation's free
phase leaves it no gain, and claims nothing (run 14's 107106018, run 15's 109106010). This study measures what a
rule on the *pattern* would see: the delay search of the diagnosis records the delays whose replay oscillates at
the measured frequency on the oscillating training run (``oscillation["reproduced_by"]``); the one the spectrum
test would pick (:func:`drakecreep.gap.drive_fit._reproducing_pick`) is replayed with the fitted model on the five
held-out runs, and each run's measured and replayed force are compared: does the model oscillate at the measured
frequency (+-15 %, :func:`drakecreep.gap.residuals.oscillates_at`) on the held-out runs that oscillate, and stay
quiet on those that do not (a quiet run checked at the training runs' frequency, as the spectrum test does)?

The rule measured (3db): the pick is claimed when at least one held-out run oscillates, the pick oscillates on every
one of them at its measured frequency and on none of the quiet ones, and on the training runs it oscillates on the
oscillating one and on none of the quiet ones (the exact on/off pattern of all nine runs). Measured in session 94
on the five development datasets with an oscillating held-out run: it passed on 2 (within a tick of the truth's
delay), under the 3 declared, so the product does not claim on it (rows
``analysis/gap_benchmark_drakecreep_dev_3db.json``).

Each dataset is diagnosed on the declared params file with its default uncertain fields, with the delay alone as
candidate, and with ``--max-nfev`` evaluations of the nominal fit: default 20, ``diagnose_drive``'s and so the
benchmark's (:func:`drakecreep.gap.benchmark.evaluate` passes its own ``max_nfev`` 6 only to the ``p_p_cascade``
kind; the first run of 3db took 6, believing otherwise). The delay is the only candidate, as the reproducing delays
come from its search and the others do not take part in it; every delay that reproduces the
training run is replayed on the held-out runs too, so the row shows whether the pick mattered. Development seeds
only (``SEED:WITHHELD:AXIS`` below the held-out seeds).

Run from the repository root (each dataset 3-13 min on one core; the diagnosis's finished steps are kept in
``--checkpoints DIR`` so a stopped run resumes)::

    PYTHONPATH=.:analysis python analysis/single_run_oscillation.py OUT.json 9073:control_delay:flexible ... \\
        [--checkpoints DIR]
"""

import argparse
import json
import sys
import time
from pathlib import Path

from drakecreep.errors import InputError
from drakecreep.files import check_output_file, write_text
from drakecreep.gap import benchmark as B
from study_cli import dev_spec

__all__ = ["pattern", "rule", "study_dataset", "summary", "main"]


def pattern(measured, model, dt, fallback_hz):
    """Run by run, the measured oscillation and whether ``model`` oscillates at its frequency.

    Parameters
    ----------
    measured, model : sequence of array_like
        Measured and replayed force of each run [N].
    dt : float
        Sample time [s].
    fallback_hz : float
        The frequency a quiet run's replay is checked at (the training runs' oscillation).

    Returns
    -------
    list of dict
        ``measured`` (the run oscillates: a quarter of its variance in its dominant oscillation above 20 Hz),
        ``measured_hz``, ``model`` (the replay oscillates within +-15 % of the measured frequency, or of
        ``fallback_hz`` on a quiet run) and ``model_hz`` (the replay's dominant frequency).
    """
    from drakecreep.gap.residuals import OSCILLATION_SHARE, dominant_oscillation, oscillates_at

    out = []
    for m, s in zip(measured, model):
        wave = dominant_oscillation(m, dt)
        on = bool(wave["share"] >= OSCILLATION_SHARE)
        hit, o = oscillates_at(s, dt, wave["freq_Hz"] if on else fallback_hz)
        out.append({"measured": on, "measured_hz": float(wave["freq_Hz"]), "model": bool(hit),
                    "model_hz": float(o["freq_Hz"]), "model_share": float(o["share"])})
    return out


def rule(train_flags, train_model, held):
    """The rule of 3db on one delay: ``(passes, why)``. ``train_flags``: the measured training runs that
    oscillate; ``train_model``: those on which the delay's replay oscillates at the measured frequency; ``held``:
    :func:`pattern` of the held-out runs."""
    if not any(h["measured"] for h in held):
        return False, "no held-out run oscillates"
    if list(train_flags) != list(train_model):
        return False, "the training runs' on/off pattern is not the measured one"
    if any(h["measured"] != h["model"] for h in held):
        return False, "the held-out runs' on/off pattern is not the measured one"
    return True, "the on/off pattern of every run matches"


def study_dataset(seed, withheld, axis, checkpoint=None, progress=None, max_nfev=20):
    """One row of the study (module docstring); ``max_nfev``: the nominal fit's evaluations."""
    from drakecreep.gap.drive_fit import _reproducing_pick, _with, diagnose_drive
    from drakecreep.gap.drake_replay import replay_drakecreep
    from drakecreep.gap.residuals import oscillates_at

    t0 = time.perf_counter()
    ds = B.generate_dataset(seed, withheld=withheld, kind="drakecreep", axis=axis)
    res = diagnose_drive(ds.train, ds.test, effects=("control_delay",), max_nfev=max_nfev, progress=progress or False,
                         checkpoint=checkpoint)
    row = {"seed": seed, "withheld": list(withheld), "axis": axis, "truth": dict(ds.truth.effects),
           "max_nfev": max_nfev, "warnings": list(res.warnings),
           "claimed": list(res.claimed), "oscillation": None, "delays": [], "pick": None}
    osc = res.oscillation
    dt = ds.train[0].dt
    if osc is not None:
        row["oscillation"] = {k: osc.get(k) for k in ("freq_Hz", "rms", "runs", "of", "oscillating", "held_out")}
        for rep in osc.get("reproduced_by") or []:
            params = _with(res.nominal, {rep["path"]: rep["value"]})
            train_sims = [replay_drakecreep(r, params) for r in ds.train]
            train_model = [bool(oscillates_at(s.force, dt, osc["freq_Hz"])[0]) for s in train_sims]
            held = pattern([r.force for r in ds.test], [replay_drakecreep(r, params).force for r in ds.test], dt,
                           osc["freq_Hz"])
            passes, why = rule(osc["oscillating"], train_model, held)
            row["delays"].append({"value": rep["value"], "freq_Hz": rep["freq_Hz"], "rms": rep["rms"],
                                  "train_model": train_model, "held_out": held, "passes": passes, "why": why})
        if osc.get("reproduced_by"):
            row["pick"] = _reproducing_pick(osc)["value"]
    row["seconds"] = time.perf_counter() - t0
    return row


def summary(row):
    """One line of a row."""
    truth = (row["truth"].get("control_delay") or {}).get("delay_samples")
    osc = row["oscillation"]
    head = f"{row['seed']} {'/'.join(row['withheld']) or 'null'} truth {truth} samples"
    if osc is None:
        return head + ": no training run oscillates where the fitted model does not"
    held = osc.get("held_out") or {}
    head += (f"; {osc['runs']} of {osc['of']} training runs oscillate at {osc['freq_Hz']:.0f} Hz, held-out "
             f"{held.get('runs', '?')} of {held.get('of', '?')}; pick {row['pick']}")
    parts = [f"{d['value']:g} ticks at {d['freq_Hz']:.0f} Hz: held-out model "
             + "".join("1" if h["model"] else "0" for h in d["held_out"]) + " measured "
             + "".join("1" if h["measured"] else "0" for h in d["held_out"]) + f", {d['why']}" for d in row["delays"]]
    return head + ("; " + "; ".join(parts) if parts else "; no delay reproduces it")


def main(argv=None):
    """Parse ``argv``, study each dataset and print its line; the exit status (2 on a bad argument, 1 when a dataset
    failed)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", metavar="OUT.json", help="rows file, rewritten after each dataset")
    ap.add_argument("datasets", nargs="+", type=dev_spec, metavar="SEED:WITHHELD:AXIS",
                    help="a development dataset of the drakecreep kind")
    ap.add_argument("--checkpoints", metavar="DIR", help="keep each diagnosis's finished steps in DIR/<seed>.pkl")
    ap.add_argument("--max-nfev", type=int, default=20, help="evaluations of the nominal fit (default 20, the "
                    "benchmark's)")
    a = ap.parse_args(argv)
    try:
        check_output_file(a.out, "OUT.json")
    except InputError as e:
        ap.exit(2, f"single_run_oscillation: error: {e}\n")
    if not 1 <= a.max_nfev <= 1000:
        ap.exit(2, f"single_run_oscillation: error: --max-nfev: got {a.max_nfev}; allowed: an integer in [1, 1000]\n")
    if a.checkpoints and Path(a.checkpoints).is_file():
        ap.exit(2, f"single_run_oscillation: error: --checkpoints: got {a.checkpoints!r}; allowed: a folder\n")
    rows, failed = [], []
    for seed, withheld, axis in a.datasets:
        ckpt = None if not a.checkpoints else Path(a.checkpoints) / f"{seed}.pkl"
        try:
            row = study_dataset(seed, withheld, axis, checkpoint=ckpt, max_nfev=a.max_nfev)
        except Exception as err:  # noqa: BLE001  (one dataset's failure is kept and the others go on)
            failed.append({"seed": seed, "error": f"{type(err).__name__}: {err}"})
            print(f"{seed}: failed ({failed[-1]['error']})", flush=True)
        else:
            rows.append(row)
            print(summary(row) + f" ({row['seconds']:.0f} s)", flush=True)
        write_text(a.out, json.dumps({"datasets": rows, "failed": failed}, indent=1, default=str))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
