"""EMPS through the Drake model: identify on the estimation file, rank effects on its held-out cycles,
augment, refit on the whole estimation file, then replay the validation file ONCE with everything fixed.

1. ``DATA_EMPS.mat`` is split at every reversal of the reference (half cycles); even parts train, odd
   parts are held out (both sets hold both directions).
2. Nominal: IDIM-LS start + output-error refinement of viscous, Coulomb, offset through the Drake replay
   (:mod:`drakecreep.gap.identify`).
3. Each candidate of :data:`drakecreep.gap.drake_effects.DRAKE_EFFECTS` and the computation delay is
   fitted on the training cycles (nominal friction refined with it) and replayed, fixed, on the held-out
   parts. An effect passes when its held-out force error is lower than the nominal's by more than twice
   the standard error of the per-part differences (paired; derived from the data, not a constant).
4. Greedy forward selection among those that pass, best first: each is refitted on top of the model
   augmented so far and kept only if it again passes against that model.
5. The kept effects are switched in together and refitted on the whole estimation file; that model is
   replayed in closed loop on ``DATA_EMPS_PULSES.mat`` (never used before this line) and its position /
   velocity / acceleration / force errors are printed beside the published rigid model's.

Run: ``python analysis/emps_drake.py [--max-nfev N] [--effects a,b,...]`` (minutes on a shared 2-core machine).
"""

import argparse
import math
import time

import numpy as np

from drakecreep.gap.drake_effects import DRAKE_EFFECTS, NOT_RANKED, fit_delay, fit_effect, score_parameters
from drakecreep.gap.drake_replay import DrakeReplay, drake_replay_errors
from drakecreep.gap.identify import identify
from drakecreep.gap.measured import load_emps
from drakecreep.gap.replay import PUBLISHED_REPLAY_ERRORS

SIGNALS = ("position", "velocity", "acceleration", "force")


def row(label, errors):
    return f"{label:44s} " + " ".join(f"{errors[s]:9.4g}" for s in SIGNALS)


def describe(fit):
    if fit.name == "control_delay":
        return f"delay {fit.delay:.2f} samples"
    return ", ".join(f"{k}={fit.parameters[k]:.4g}" for k in DRAKE_EFFECTS[fit.name].parameters)


def paired_gain(nominal, candidate):
    """Mean and standard error of the per-cycle held-out force error decrease [points of %]."""
    d = np.array([nominal[k]["force"] - candidate[k]["force"] for k in nominal])
    return float(d.mean()), float(d.std(ddof=1) / math.sqrt(d.size)) if d.size > 1 else float("inf")


def split_half_cycles(run):
    """Parts of ``run`` between reversals of the reference (label ``<label>@<i>``)."""
    import dataclasses

    v = np.gradient(run.x_ref, run.dt)
    s = np.sign(v) * (np.abs(v) > 0.01 * np.max(np.abs(v)))
    nz = np.flatnonzero(s)
    flips = nz[1:][np.diff(s[nz]) != 0]
    cuts = [0] + [int(c) for c in flips] + [run.n]
    parts = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        if b - a >= 500:
            parts.append(dataclasses.replace(run.slice(a, b), label=f"{run.label}@{len(parts)}"))
    return parts


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--max-nfev", type=int, default=6, help="least-squares evaluations per start")
    ap.add_argument("--effects", default=",".join(list(DRAKE_EFFECTS) + ["control_delay"]))
    args = ap.parse_args()
    t_start = time.perf_counter()
    est = load_emps("estimation").run()
    cycles = split_half_cycles(est)
    train, held = cycles[0::2], cycles[1::2]
    print(f"estimation file: {len(cycles)} parts between reversals, {len(train)} train / {len(held)} held out")
    nominal = identify(train, ("viscous", "coulomb", "offset"), max_nfev=args.max_nfev)
    print("\n".join(nominal.summary()))
    nom_held, nom_rms = score_parameters(held, nominal.parameters)
    print(f"nominal: held-out force error {nom_rms:.3f} % (rms over cycles)   [{time.perf_counter() - t_start:.0f} s]")
    passed = []
    print(f"{'effect':22s} {'train F%':>9s} {'held F%':>9s} {'gain':>8s} {'+-2se':>8s} {'s':>6s}")
    for name in args.effects.split(","):
        name = name.strip()
        fit = fit_delay(train, held, nominal) if name == "control_delay" else \
            fit_effect(name, train, held, nominal, max_nfev=args.max_nfev)
        gain, se = paired_gain(nom_held, fit.test_errors)
        if gain > 2 * se:
            passed.append((gain, fit))
        print(f"{name:22s} {fit.train_force_error:9.3f} {fit.test_force_error:9.3f} {gain:8.3f} {2 * se:8.3f} "
              f"{fit.seconds:6.0f}{'  passes' if gain > 2 * se else ''}  {describe(fit)}", flush=True)
    for name, why in NOT_RANKED.items():
        print(f"{name:22s} not ranked: {why}")
    # greedy forward selection, best single gain first
    passed.sort(key=lambda gf: -gf[0])
    kept, current, current_held = [], None, nom_held
    fitted = ["viscous", "coulomb", "offset"]
    for _, fit in passed:
        if current is not None:
            fit = fit_delay(train, held, current) if fit.name == "control_delay" else \
                fit_effect(fit.name, train, held, current, max_nfev=args.max_nfev, refit=tuple(fitted))
        gain, se = paired_gain(current_held, fit.test_errors)
        keep = gain > 2 * se
        print(f"  + {fit.name:20s} on top of {' + '.join(f.name for f in kept) or 'nominal'}: held {fit.test_force_error:.3f} %, "
              f"gain {gain:.3f} +- {2 * se:.3f} -> {'KEPT' if keep else 'dropped'}", flush=True)
        if keep:
            kept.append(fit)
            current, current_held = fit, fit.test_errors
            if fit.name != "control_delay":
                fitted += [p for p in DRAKE_EFFECTS[fit.name].parameters if p not in fitted]
    diag_time = time.perf_counter() - t_start
    print(f"diagnosis on the estimation file: {diag_time:.0f} s wall")

    # the augmented model: nominal + kept effects, refitted on the whole estimation file
    last = kept[-1] if kept else None
    flexible = last.flexible if last else False
    delay = last.delay if last else nominal.delay
    fixed = dict(last.parameters if last else nominal.parameters)
    final = identify([est], tuple(fitted), flexible=flexible, delay=delay, fixed=fixed, max_nfev=args.max_nfev)
    print("augmented model (" + (" + ".join(f.name for f in kept) or "nothing kept") + "), fitted on DATA_EMPS.mat:")
    print("\n".join(final.summary()))
    val = load_emps("validation").run()
    print(f"{'':44s} " + " ".join(f"{s:>9s}" for s in SIGNALS) + "   [% of ||y||]")
    print(row("published rigid IDIM model, estimation", PUBLISHED_REPLAY_ERRORS["estimation"]))
    print(row("published rigid IDIM model, validation", PUBLISHED_REPLAY_ERRORS["validation"]))
    for label, params, flex, d in (("Drake nominal (OE), estimation", nominal.parameters, False, nominal.delay),
                                   ("Drake augmented, estimation", final.parameters, flexible, delay)):
        print(row(label, drake_replay_errors(DrakeReplay(est, flexible=flex, delay=d).simulate(params))))
    for label, params, flex, d in (("Drake nominal (OE), VALIDATION", nominal.parameters, False, nominal.delay),
                                   ("Drake augmented, VALIDATION", final.parameters, flexible, delay)):
        print(row(label, drake_replay_errors(DrakeReplay(val, flexible=flex, delay=d).simulate(params))))
    print(f"total {time.perf_counter() - t_start:.0f} s wall")


if __name__ == "__main__":
    main()
