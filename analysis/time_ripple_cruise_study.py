"""Where does a fitted fixed-time-frequency force ripple help: at cruise or in the time-locked moves?

Development seeds, and seeds of held-out runs already looked into (never a run's own seeds before it is
scored). Every run of the benchmark's truth has the same timing (out leg from 0.2 s, back
leg from 1.7 s, 20 % raised-cosine ramps; :func:`drakecreep.gap.truth.draw_profiles`), so a model error that
follows the reference (a mass, a lag, a friction law) repeats at the same instants in every run, and a
sinusoid of fixed phase can fit part of it. A true force ripple at a fixed time frequency is there at cruise
as well. For each dataset this script fits only the ``time_ripple`` candidate with the product diagnosis, then
replays the nominal and the ripple model on the held-out and the audit runs and splits each run's log error
ratio between the cruise samples (reference speed within 2 % of its peak) and the rest. The product's test
(``DrakeEffect.regime``) came after this study and uses the regime classifier's ``constant_speed`` samples
(:func:`drakecreep.gap.residuals.classify_regimes`) instead of this script's cruise.

Usage: ``PYTHONPATH=. python analysis/time_ripple_cruise_study.py OUT.json SEED:EFFECT [...]``
(``EFFECT`` is ``null`` or a withheld effect, e.g. ``14000:null 9000:time_ripple``).
"""

import json
import sys

import numpy as np

from drakecreep.files import write_text
from drakecreep.gap import benchmark
from drakecreep.gap.drake_replay import drake_replay
from study_cli import case_type, out_and_cases

#: the argparse type of one dataset on the command line
CASE = case_type(("null",) + tuple(benchmark.T.WITHHELD), "none", "14000:null or 9000:time_ripple")


def _split_log_ratios(runs, nominal, candidate):
    out = []
    for run in runs:
        a = drake_replay(run, nominal["parameters"], flexible=nominal["flexible"], delay=nominal["delay"])
        b = drake_replay(run, candidate["parameters"], flexible=candidate["flexible"], delay=candidate["delay"])
        v = np.abs(np.gradient(np.asarray(run.x_ref, dtype=float), run.dt))
        cruise = v > 0.98 * v.max()
        ea = np.asarray(run.force, dtype=float) - a.force
        eb = np.asarray(run.force, dtype=float) - b.force
        row = {}
        for name, sel in (("cruise", cruise), ("rest", ~cruise), ("all", np.ones_like(cruise))):
            row[name] = 0.5 * float(np.log(np.sum(ea[sel] ** 2) / np.sum(eb[sel] ** 2)))
        row["cruise_share"] = float(cruise.mean())
        out.append(row)
    return out


def study(seed, effect):
    withheld = () if effect == "null" else (effect,)
    ds = benchmark.generate_dataset(seed, withheld=withheld, kind="p_p_cascade")
    res = benchmark.diagnose_dataset(ds, effects=["time_ripple"])
    r = res.ranking[0]
    nom = {"parameters": dict(res.nominal.parameters), "flexible": False, "delay": res.nominal.delay}
    row = {"seed": seed, "withheld": list(withheld), "axis": ds.axis, "snr": ds.snr, "claimed": list(res.claimed),
           "null": list(res.null)}
    if r.fit is None:
        row["screened_out"] = True
        return row
    cand = {"parameters": dict(r.fit.parameters), "flexible": r.fit.flexible, "delay": r.fit.delay}
    p = r.fit.parameters
    row.update(frequency_Hz=p["ripple_frequency"],
               amplitude_N=float(np.hypot(p["time_ripple_cos"], p["time_ripple_sin"])),
               log_error_ratio=r.log_ratio, test=_split_log_ratios(ds.test, nom, cand),
               audit=_split_log_ratios(ds.audit, nom, cand))
    return row


def main(argv=None):
    """Run the study on each dataset of ``argv`` (every one checked first); the exit status."""
    out, cases = out_and_cases(__doc__, CASE, "SEED:EFFECT",
                               "a dataset: EFFECT null or a withheld effect", argv)
    rows = []
    for seed, effect in cases:
        rows.append(study(int(seed), effect))
        r = rows[-1]
        if "test" in r:
            mean = {k: np.mean([x[k] for x in r["test"] + r["audit"]]) for k in ("cruise", "rest", "all")}
            print(f"{seed} {effect:12s} f {r['frequency_Hz']:.2f} Hz A {r['amplitude_N']:.2f} N LR "
                  f"{r['log_error_ratio']:+.3f} claimed {r['claimed']}; held-out+audit mean log ratio cruise "
                  f"{mean['cruise']:+.3f} rest {mean['rest']:+.3f} all {mean['all']:+.3f}", flush=True)
        else:
            print(f"{seed} {effect} screened out", flush=True)
        write_text(out, json.dumps({"rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
