"""The ``drakecreep`` kind's candidates added in session 92, fitted only when named, on runs that have the effect
and on the same runs without it.

Runs of the quick rig's diagram (:func:`drakecreep.gap.drake_replay.simulated_runs`: six out-and-back runs at
15-40 mm/s, 0.5 s at 1 kHz, 2 N of white noise on ``u``), three training and three held out, the seal force
uncertain, the one candidate named:

* ``backlash``: the nut's lost motion, 8 um (``nut.backlash``);
* ``structural_mode``: a quarter of the moving mass on a 60 Hz mode of its own (``table.mode_*``);
* ``friction_drift``: the table's friction falling 30 % per second of each run (``friction.time_drift``), behind a
  params file whose seal force is 15 % high.

Each case prints the fitted fields with their 95 % intervals, the held-out force error of the fitted params file and
of the augmented one, and what the same diagnosis claims on the runs without the effect (the same noise). The cases'
seeds are those of ``tests/gap/test_drive_fit_on_request.py`` (which checks the nulls on one other dataset, every
candidate named); ``--seed`` draws other noise (a figure the tests never saw).

With ``--together`` every case names all three candidates, so each must win against the other two (which one is
claimed first, and what the others do).

Usage: ``PYTHONPATH=. python analysis/drive_named_candidates.py [NAME ...] [--seed N] [--together]``
"""

import argparse
import sys
import time

from drakecreep.gap.drake_replay import quick_replay_params, rms_force_error, simulated_runs
from drakecreep.gap.drive_fit import diagnose_drive
from drakecreep.params import get_value, preset, with_value

SPEEDS = (0.02, 0.03, 0.025, 0.035, 0.015, 0.04)
#: name -> (the truth's fields, the params file's fields besides the rig's, the tests' noise seed)
CASES = {
    "backlash": ({"nut.backlash": 8e-6}, {}, 1200),
    "structural_mode": ({"table.mode_mass_share": 0.25, "table.mode_frequency": 60.0}, {}, 1500),
    "friction_drift": ({"friction.time_drift": -0.3}, {"table.seal_force": 1.15 * 4.0}, 1800),
}


def _set(params, values):
    for path, value in values.items():
        params = with_value(params, path, value)
    return params


def main(argv=None):
    """Diagnose each case and its null; the exit status."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("names", nargs="*", metavar="NAME", help="cases to run (default all: " + ", ".join(CASES) + ")")
    ap.add_argument("--seed", type=int, help="noise seed of every case (default: the tests' own, per case)")
    ap.add_argument("--together", action="store_true", help="name all three candidates in every case")
    args = ap.parse_args(argv)
    for name in args.names:
        if name not in CASES:
            ap.error(f"NAME: got {name!r}; allowed: one of {', '.join(CASES)}")
    if args.seed is not None and args.seed < 0:
        ap.error(f"--seed: got {args.seed}; allowed: an integer >= 0")
    rig = quick_replay_params(preset("paper"))
    for name in args.names or list(CASES):
        truth_fields, declared_fields, seed = CASES[name]
        seed = seed if args.seed is None else args.seed
        declared = _set(rig, declared_fields)
        t0 = time.perf_counter()
        runs = simulated_runs(_set(rig, truth_fields), SPEEDS, declared=declared, n=500, noise=2.0, seed=seed)
        effects = tuple(CASES) if args.together else (name,)
        res = diagnose_drive(runs[:3], runs[3:], uncertain=("table.seal_force",), effects=effects)
        plain = simulated_runs(rig, SPEEDS, declared=declared, n=500, noise=2.0, seed=seed)
        null = diagnose_drive(plain[:3], plain[3:], uncertain=("table.seal_force",), effects=effects)
        truth = ", ".join(f"{p} = {v:g}" for p, v in {**truth_fields, "table.seal_force": rig.table.seal_force}.items())
        print(f"{name} (seed {seed}; truth {truth}):")
        print(f"  claimed: {' + '.join(res.claimed) or 'nothing'}; held-out force error "
              f"{rms_force_error(res.nominal_test_errors):.2f} % -> {rms_force_error(res.test_errors):.2f} %")
        for p in res.fitted:
            print(f"  {p.path} = {p.value:.4g} {p.unit} (95 % interval {p.lower:.4g} .. {p.upper:.4g})")
        for path in truth_fields:
            if path not in {p.path for p in res.fitted}:
                print(f"  {path} = {get_value(res.params, path):.4g} (searched, no interval)")
        if args.together:
            for c in res.candidates:
                print(f"  {c.name}: training gain {100 * c.train_gain:+.1f} %, {c.reason}")
        gains = ", ".join(f"{c.name} {100 * c.train_gain:+.1f} %" for c in null.candidates)
        print(f"  without the effect: claimed {' + '.join(null.claimed) or 'nothing'} (training gains {gains}); "
              f"{time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
