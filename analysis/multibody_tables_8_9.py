"""Tables 8-9 (the paper's measured speed fluctuation) with the multibody model beside the two-mass model.

The same five experiments (load case / feed: LC1 1, LC2 1, LC3 1, LC3 0.5, LC3 2 mm/s) and the same method
as ``docs/tables_8_9.md`` (:mod:`drakecreep.studies.table_fluctuation`): per experiment and model, one 5 s
Drake run of the base model (``paper`` preset, none of the four effects) and one with a unit force ripple
(1 N at the nominal 5 Hz), the table position read through the linear scale and differenced every 1 ms,
``max |v - mean v|`` from t = 1 s. Then, per model, the hypotheses the multibody model can carry (force
ripple, grating interpolation error, scale quantization, and their pairs; the lead error is a two-mass
model effect: the ``ScrewJoint``'s lead is exact) are fitted on all five experiments and held out one at a
time (:func:`~drakecreep.studies.table_fluctuation.leave_one_out`), and the two-mass model's fitted
amplitudes are applied unchanged to the multibody model (a prediction with no refit).

Each simulate() call runs with the convergence check on (the preset's default); a run whose check fails is
reported. Writes ``tables_8_9.json`` to ``--out``.

    python analysis/multibody_tables_8_9.py [--models two_mass rigid3_axial] [--out out/multibody_tables_8_9]
"""

from __future__ import annotations

import argparse
import json
import time
from itertools import combinations
from pathlib import Path

import numpy as np

from drakecreep.params import with_value
from drakecreep.scenario import Scenario
from drakecreep.sim.simulation import simulate
from drakecreep.studies.table_fluctuation import (
    DURATION,
    EFFECTS,
    Responses,
    _shape_values,
    base_params,
    experiments,
    leave_one_out,
    predict,
)
from multibody_vs_two_mass import BOUNDARY_MODELS  # analysis/ is sys.path[0] when run as a script

__all__ = ["MODELS", "HYPOTHESES", "model_responses", "main"]

#: name -> simulate() keyword arguments (the creep-boundary comparison's models)
MODELS = BOUNDARY_MODELS

#: the hypotheses both models can carry (no lead error)
_CARRIED = ("force_ripple", "grating", "quantization")
HYPOTHESES = tuple((e,) for e in _CARRIED) + tuple(combinations(_CARRIED, 2))


def _run(params, exp, kwargs):
    start = time.process_time()
    r = simulate(params, Scenario(feed=exp["feed_mm_s"] * 1e-3, load_case=exp["load_case"], duration=DURATION),
                 **kwargs)
    if r.metrics is None or not r.ok:
        raise RuntimeError(f"LC{exp['load_case']} {exp['feed_mm_s']:g} mm/s: {r.status}")
    info = dict(cpu_s=time.process_time() - start, converged=r.metrics.converged,
                table_speed_fluctuation_mm_s=r.metrics.max_fluctuation * 1e3)
    return np.asarray(r.time), np.asarray(r.signals["table_position"]), info


def model_responses(params, exps, shapes, kwargs, log=print):
    """``(load_case, feed) -> Responses`` (base run and the unit force ripple's response) and run information."""
    ripple_key = ("force_ripple", shapes["disturbance.ripple_frequency"])
    unit = with_value(params, EFFECTS["force_ripple"].field, EFFECTS["force_ripple"].unit)
    out, info = {}, {}
    for e in exps:
        key = (e["load_case"], e["feed_mm_s"])
        t, x0, i0 = _run(params, e, kwargs)
        _, x1, i1 = _run(unit, e, kwargs)
        out[key] = Responses(e["load_case"], e["feed_mm_s"], t, x0, {ripple_key: x1 - x0},
                             steady_start=params.simulation.steady_start)
        info[f"LC{key[0]} {key[1]:g}"] = dict(base=i0, unit_ripple=i1)
        log(f"    LC{key[0]} {key[1]:g} mm/s: base {i0['cpu_s']:.0f} s CPU (converged {i0['converged']}), "
            f"unit ripple {i1['cpu_s']:.0f} s (converged {i1['converged']})", flush=True)
    return out, info


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--models", nargs="+", default=["two_mass", "rigid3_axial"], choices=sorted(MODELS))
    ap.add_argument("--out", default="out/multibody_tables_8_9")
    args = ap.parse_args(argv)
    if args.models[0] != "two_mass":
        args.models = ["two_mass"] + [m for m in args.models if m != "two_mass"]
    params = base_params()
    shapes = _shape_values(params)
    exps = experiments()
    labels = [f"LC{e['load_case']} {e['feed_mm_s']:g}" for e in exps]
    result = dict(experiments=exps, models={})
    responses = {}
    for name in args.models:
        print(f"{name}:", flush=True)
        responses[name], info = model_responses(params, exps, shapes, MODELS[name])
        result["models"][name] = dict(runs=info)

    def fmt(values):
        return " | ".join(f"{v:.4f}" for v in values)

    print("\nMeasured speed fluctuation (mm/s; the scale's reading differenced every 1 ms, t >= 1 s of 5 s)")
    print("| model / hypothesis | " + " | ".join(labels) + " |")
    print("| --- |" + " --- |" * len(labels))
    print("| experiment (paper) | " + fmt(e["experiment_mm_s"] for e in exps) + " |")
    for name in args.models:
        base = [predict(responses[name][(e["load_case"], e["feed_mm_s"])], {}, shapes) * 1e3 for e in exps]
        result["models"][name]["base_mm_s"] = base
        print(f"| {name}, base model (no effect) | " + fmt(base) + " |")

    fits = {}
    for name in args.models:
        fits[name] = {"+".join(h): leave_one_out(h, responses[name], exps, shapes) for h in HYPOTHESES}
        result["models"][name]["hypotheses"] = fits[name]
    for h in ("force_ripple+grating", "grating+quantization", "force_ripple+quantization"):
        two = fits["two_mass"][h]
        amps = {k: v / EFFECTS[k].scale for k, v in
                ((key.rsplit("_", 1)[0], val) for key, val in two["amplitudes"].items())}
        print(f"| {h}: two_mass in-sample ({', '.join(f'{k} {v:.3g}' for k, v in two['amplitudes'].items())}) | "
              + fmt(p["in_sample_mm_s"] for p in two["experiments"]) + " |")
        for name in args.models[1:]:
            same = [predict(responses[name][(e["load_case"], e["feed_mm_s"])], amps, shapes) * 1e3 for e in exps]
            result["models"][name].setdefault("two_mass_amplitudes_mm_s", {})[h] = same
            err = [(s - e["experiment_mm_s"]) / e["experiment_mm_s"] * 100 for s, e in zip(same, exps)]
            print(f"| {h}: {name} with the two-mass amplitudes (error % {', '.join(f'{x:+.1f}' for x in err)}) | "
                  + fmt(same) + " |")

    print("\nLeave-one-out per model (each model fitted on its own runs)")
    print("| hypothesis | model | amplitudes (all five) | in-sample RMS (%) | held-out mean abs (%) | held-out max (%) |")
    print("| --- | --- | --- | --- | --- | --- |")
    for h in ("+".join(x) for x in HYPOTHESES):
        for name in args.models:
            f = fits[name][h]
            amps = ", ".join(f"{k} {v:.3g}" for k, v in f["amplitudes"].items())
            print(f"| {h} | {name} | {amps} | {f['in_sample_rms_percent']:.1f} | {f['held_out_mean_abs_percent']:.1f} "
                  f"| {f['held_out_max_abs_percent']:.1f} |")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "tables_8_9.json").write_text(json.dumps(result, indent=1, default=str))
    print(f"wrote {out / 'tables_8_9.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
