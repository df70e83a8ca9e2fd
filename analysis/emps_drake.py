"""EMPS through the Drake model: identify on the estimation file, rank effects on its held-out cycles,
augment, refit on the whole estimation file, then replay the validation file ONCE with everything fixed.

1. ``DATA_EMPS.mat`` is split at every reversal of the reference (half cycles); alternate pairs of
   half cycles train and are held out (both sets hold both directions: with even/odd half cycles every
   training part moved forward and Coulomb friction and offset could not be separated).
2. Nominal: IDIM-LS start + output-error refinement of viscous, Coulomb, offset through the Drake replay
   (:mod:`drakecreep.gap.identify`).
   (steps 2-4 are :func:`drakecreep.gap.drake_diagnosis.diagnose_drake`; the augmented model is also
   written to ``emps_augmented.yaml``)
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
import time


from drakecreep.gap.drake_diagnosis import diagnose_drake
from drakecreep.gap.drake_effects import DRAKE_EFFECTS, NOT_RANKED
from drakecreep.gap.drake_replay import DrakeReplay, drake_replay_errors, make_replay
from drakecreep.gap.identify import identify
from drakecreep.gap.measured import load_emps
from drakecreep.gap.runs import split_half_cycles  # noqa: F401 (used here and by bench_diagnose)
from drakecreep.gap.replay import PUBLISHED_REPLAY_ERRORS

SIGNALS = ("position", "velocity", "acceleration", "force")


def row(label, errors):
    return f"{label:44s} " + " ".join(f"{errors[s]:9.4g}" for s in SIGNALS)


def describe(fit):
    if fit.name == "control_delay":
        return f"delay {fit.delay:.2f} samples"
    return ", ".join(f"{k}={fit.parameters[k]:.4g}" for k in DRAKE_EFFECTS[fit.name].parameters)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--max-nfev", type=int, default=6, help="least-squares evaluations per start")
    ap.add_argument("--effects", default=",".join(list(DRAKE_EFFECTS) + ["control_delay"]))
    args = ap.parse_args()
    t_start = time.perf_counter()
    est = load_emps("estimation").run()
    cycles = split_half_cycles(est)
    # alternate PAIRS of half cycles (one out, one back) so that both sets move both ways
    train = [p for i, p in enumerate(cycles) if i % 4 in (0, 1)]
    held = [p for i, p in enumerate(cycles) if i % 4 in (2, 3)]
    print(f"estimation file: {len(cycles)} parts between reversals, {len(train)} train / {len(held)} held out")
    diag = diagnose_drake(train, held, [e.strip() for e in args.effects.split(",")], max_nfev=args.max_nfev,
                          progress=lambda line: print(f"  [{time.perf_counter() - t_start:5.0f} s] {line}", flush=True))
    nominal = diag.nominal
    print("\n".join(nominal.summary()))
    print(f"{'effect':22s} {'train F%':>9s} {'held F%':>9s} {'gain':>8s} {'+-2se':>8s} {'s':>6s}")
    for r in diag.ranking:
        if r.screened_out:
            print(f"{r.name:22s} screened out on inverse dynamics: held-out gain {r.screen.gain:+.3f} "
                  f"+- {2 * r.screen.standard_error:.3f}")
            continue
        print(f"{r.name:22s} {r.fit.train_force_error:9.3f} {r.fit.test_force_error:9.3f} {r.gain:8.3f} "
              f"{2 * r.standard_error:8.3f} {r.fit.seconds:6.0f}{'  passes' if r.passes else ''}  {describe(r.fit)}")
    for name, why in NOT_RANKED.items():
        print(f"{name:22s} not ranked: {why}")
    print("\n".join(diag.summary()))
    print(f"diagnosis on the estimation file: {diag.seconds:.0f} s wall")
    diag.save_model("emps_augmented.yaml")

    validate(diag, est, args.max_nfev)
    print(f"total {time.perf_counter() - t_start:.0f} s wall")


def validate(diag, est, max_nfev=6):
    """Refit the augmented model on the whole estimation file, replay the validation file ONCE (fixed).

    Prints the table; returns ``{label: errors}``. The validation replays are done twice: by the sampled fast
    path used in the fits and by the error-controlled :class:`DrakeReplay` (a cross-check of the fast path).
    """
    nominal = diag.nominal
    fitted = list(nominal.fitted)
    for name in diag.claimed:
        if name != "control_delay":
            fitted += [p for p in DRAKE_EFFECTS[name].parameters if p not in fitted]
    flexible, delay = diag.model["flexible"], diag.model["delay"]
    final = identify([est], tuple(fitted), flexible=flexible, delay=delay, fixed=diag.model["parameters"],
                     max_nfev=max_nfev)
    print("augmented model (" + (" + ".join(diag.claimed) or "nothing claimed") + "), refitted on DATA_EMPS.mat:")
    print("\n".join(final.summary()))
    val = load_emps("validation").run()
    print(f"{'':44s} " + " ".join(f"{s:>9s}" for s in SIGNALS) + "   [% of ||y||]")
    print(row("published rigid IDIM model, estimation", PUBLISHED_REPLAY_ERRORS["estimation"]))
    print(row("published rigid IDIM model, validation", PUBLISHED_REPLAY_ERRORS["validation"]))
    out = {}
    for data, tag in ((est, "estimation"), (val, "VALIDATION")):
        for label, params, flex, d in (("Drake nominal (OE)", nominal.parameters, False, nominal.delay),
                                       ("Drake augmented", final.parameters, flexible, delay)):
            for path, rep in (("sampled", make_replay(data, flexible=flex, delay=d, free=())),
                              ("continuous", DrakeReplay(data, flexible=flex, delay=d))):
                key = f"{label}, {tag} ({path})"
                out[key] = drake_replay_errors(rep.simulate(params))
                print(row(key, out[key]))
    return out


if __name__ == "__main__":
    main()
