"""Which computation delays make the Drake model oscillate on the same training runs as a benchmark dataset's truth.

For development datasets with a withheld control delay (``drakecreep`` kind, flexible axis; docs/gap_benchmark.md
3ci): the first four training runs replayed through the declared params file with each delay of a grid (speed-loop
ticks), the truth's other values as declared. Per run it prints the replay's and the measurement's force RMS in the
band of the measured oscillation (at the median oscillation's frequency on a run that does not oscillate), ``Y``
where the replay oscillates there (:func:`drakecreep.gap.residuals.oscillates_at`), and per delay the mean
``|ln(replayed / measured)|`` over the runs: the run-by-run spectral match a delay's claim could be decided on.
Not the diagnosis: its fitted friction differs from the declared file's.

Usage: ``PYTHONPATH=. python analysis/delay_pattern_study.py SEED [SEED ...] [--ticks 0,1,2,4,6,8,10,12,16]``
(development seeds only, below ``benchmark.HELDOUT_SEEDS``).
"""

import argparse
import math
import sys

import numpy as np

from drakecreep.gap import benchmark as B
from drakecreep.gap.drake_replay import replay_drakecreep
from drakecreep.gap.residuals import _band_rms, _welch, dominant_oscillation, oscillates_at, sustained_oscillation
from drakecreep.params import with_value

__all__ = ["band_rms", "study", "main"]


def band_rms(record, dt, freq):
    """RMS of ``record`` in the band of +-15 % around ``freq`` [Hz] (the band of the oscillation tests)."""
    f, p, df = _welch(np.asarray(record, dtype=float), dt)
    return _band_rms(f, p, df, freq)


def study(seed, ticks, out=print):
    """Print the table of one dataset (see the module docstring)."""
    ds = B.generate_dataset(seed, withheld=("control_delay",), kind="drakecreep", axis="flexible")
    runs = ds.train[:4]
    base = runs[0].meta.params
    nominal = [replay_drakecreep(r, base) for r in runs]
    osc = sustained_oscillation([r.force for r in runs], [s.force for s in nominal], runs[0].dt)
    out(f"{seed}: truth {B.true_drive_values(ds.truth)}; measured oscillation "
        + ("none" if osc is None else f"{osc['freq_Hz']:.0f} Hz on {osc['runs']} of {osc['of']} runs"))
    if osc is None:
        return
    measured = [dominant_oscillation(r.force, r.dt) for r in runs]
    for d in ticks:
        p = with_value(base, "controller.computation_delay", float(d))
        cells, errs = [], []
        for r, s, m in zip(runs, (replay_drakecreep(r, p) for r in runs), measured):
            f = m["freq_Hz"] if m["share"] >= 0.5 else osc["freq_Hz"]
            hit, _ = oscillates_at(s.force, r.dt, f)
            b_sim, b_meas = band_rms(s.force, r.dt, f), band_rms(r.force, r.dt, f)
            errs.append(abs(math.log(max(b_sim, 1e-9) / max(b_meas, 1e-9))))
            cells.append(f"{'Y' if hit else '.'} {b_sim:7.1f} / {b_meas:7.1f} N")
        out(f"{d:3d} ticks | " + " | ".join(cells) + f" | mean |ln| {np.mean(errs):.2f} Np")


def main(argv=None):
    """Parse ``argv`` and print each dataset's table; the exit status (2 on a bad argument)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("seeds", nargs="+", type=int, metavar="SEED")
    ap.add_argument("--ticks", default="0,1,2,4,6,8,10,12,16", help="delays to replay [speed-loop ticks]")
    a = ap.parse_args(argv)
    try:
        ticks = [int(t) for t in a.ticks.split(",")]
    except ValueError:
        ap.exit(2, f"delay_pattern_study: error: --ticks: got {a.ticks!r}; allowed: whole numbers, comma separated\n")
    if any(t < 0 for t in ticks):
        ap.exit(2, f"delay_pattern_study: error: --ticks: got {a.ticks!r}; allowed: whole numbers >= 0\n")
    for seed in a.seeds:
        if seed >= B.HELDOUT_SEEDS:
            ap.exit(2, f"delay_pattern_study: error: SEED: got {seed}; allowed: a seed below {B.HELDOUT_SEEDS} "
                    "(held-out seeds are spent in a pre-registered run only)\n")
    for seed in a.seeds:
        study(seed, ticks)
    return 0


if __name__ == "__main__":
    sys.exit(main())
