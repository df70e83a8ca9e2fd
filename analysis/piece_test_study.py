"""Would a test over pieces of the held-out runs claim the lead errors carried by one or two fast runs?

Development study on spent held-out seeds (runs already scored and looked into; never a run's own seeds before it
is scored). docs/gap_benchmark.md, 3ag: a lead error's force is the table's inertia times ``e''(x) v^2``, so only the
fastest held-out runs carry it; with five held-out runs the sign-flip p value of a gain carried by k runs is about
``2^-(k+1)``, and the t test fails on the spread between carrying and empty runs. The only way to more
independent evidence is pieces of the runs; friction drift makes the pieces of one run share their level.

For each dataset this script diagnoses it with the product path (``benchmark.diagnose_dataset``) and, for each
fitted candidate whose reference is the nominal (not a ``screen_refits`` one), reads the held-out errors of each
run's quarters the diagnosis already has (``force_piece_<i>`` of
:func:`drakecreep.gap.drake_replay.drake_replay_errors`, :data:`~drakecreep.gap.drake_replay.RUN_PIECES` per run),
and prints per candidate:

* the product's own numbers: per-run plain log ratios, mean, whether it passes;
* per-piece ``ln(e_nominal / e_candidate)`` of the force error, and the sign-flip p value of their mean over all
  pieces (``drakecreep.gap.claims.sign_flip_p``: 19 999 random sign patterns with a fixed seed for 20 pieces).

Usage: ``PYTHONPATH=. python analysis/piece_test_study.py OUT.json SEED:WITHHELD:AXIS [...]``
(``WITHHELD`` ``null`` or an effect, ``AXIS`` ``rigid`` or ``flexible``). The rows of session 40 (code before the
piece test) are in ``analysis/piece_test_dev.json``; the product had no piece errors then, and this script
replayed the held-out runs again for them, over the same equal windows.
"""

import json
import sys
import time

import numpy as np

from drakecreep.files import write_text
from drakecreep.gap import benchmark
from drakecreep.gap.claims import sign_flip_p
from drakecreep.gap.drake_diagnosis import run_log_ratios
from drakecreep.gap.drake_effects import DRAKE_EFFECTS
from drakecreep.gap.drake_replay import RUN_PIECES, piece_keys
from study_cli import out_and_specs


def study(seed, withheld, axis):
    t0 = time.perf_counter()
    ds = benchmark.generate_dataset(seed, withheld=withheld, kind="p_p_cascade", axis=axis)
    res = benchmark.diagnose_dataset(ds)
    rows = []
    for r in res.ranking:
        if r.screened_out or r.reference_errors is not None:
            continue
        fit = r.fit
        # rows: held-out runs; columns: their quarters in time order
        pieces = np.column_stack([run_log_ratios(res.nominal_test_errors, fit.test_errors, k) for k in piece_keys()])
        runs = run_log_ratios(res.nominal_test_errors, fit.test_errors, "force")
        rows.append({"effect": r.name, "passes": bool(r.passes), "gain": float(r.gain),
                     "log_ratio": float(r.log_ratio), "run_log_ratios": [float(v) for v in runs],
                     "piece_log_ratios": pieces.tolist(), "piece_mean": float(pieces.mean()),
                     "piece_p_sign_flip": float(sign_flip_p(pieces.ravel()))})
    ranking_names = [r.name for r in res.ranking if not r.screened_out]
    return {"seed": seed, "withheld": list(withheld), "axis": axis, "snr": float(ds.snr),
            "claimed": list(res.claimed), "null": list(res.null),
            "ranking": ranking_names, "candidates": rows, "seconds": time.perf_counter() - t0,
            "screen_refits": [n for n in ranking_names if n in DRAKE_EFFECTS and DRAKE_EFFECTS[n].screen_refits]}


def main(argv=None):
    """Run the study on each dataset of ``argv`` (every spec checked first) and write the rows; the exit status."""
    out, specs = out_and_specs(__doc__, argv)
    rows = []
    for seed, withheld, axis in specs:
        row = study(seed, withheld, axis)
        rows.append(row)
        print(f"{seed} {'+'.join(withheld) or 'null'} {axis}: claimed {row['claimed']}, null {row['null'][0]:.3f}, "
              f"{row['seconds']:.0f} s", flush=True)
        for c in row["candidates"]:
            print(f"   {c['effect']:22s} passes {c['passes']!s:5s} mean {c['log_ratio']:+.3f} runs "
                  f"{np.round(c['run_log_ratios'], 3).tolist()} pieces mean {c['piece_mean']:+.3f} "
                  f"p {c['piece_p_sign_flip']:.3g}", flush=True)
        write_text(out, json.dumps({"note": "piece test study on spent held-out datasets (session 40)",
                                    "pieces": RUN_PIECES, "datasets": rows}, indent=1, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())
