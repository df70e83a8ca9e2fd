"""The delay search's run-by-run record in benchmark rows: does every training run want the delay fitted on all?

For each row whose ``control_delay`` candidate kept its search (``ranking[].search``, docs/gap_benchmark.md 3cr):
the delay fitted on all the training runs, whether it passed, its training gain, each run's own best delay, and the
two figures 3cr named before its withheld delays were read: **agreement** (the share of runs whose own best delay
is the fitted one) and **runs helped** (the share of runs whose own SSE at the fitted delay is below the declared
delay's). Rows without the record (written before ``8fd19c3``) are listed as such.

Usage: ``python analysis/delay_signature.py ROWS.json [...]`` (rows of ``diagnose_dataset.py --json`` or
``bench_gap_benchmark.py --json``).
"""

import argparse
import sys

from study_cli import read_rows

__all__ = ["signature", "line", "main"]


def signature(row):
    """The delay candidate's run-by-run figures of benchmark ``row``: a dict, or None without a recorded search.

    Keys: ``fitted`` and ``declared`` [velocity-loop samples], ``passes``, ``train_gain`` (relative), ``run_best``,
    ``run_gain`` (each run's relative SSE decrease at the fitted delay against the declared one), ``agreement`` and
    ``helped`` (shares of the runs).
    """
    found = [c for c in row.get("ranking") or () if c.get("effect") == "control_delay" and c.get("search")]
    if not found:
        return None
    c, = found
    s = c["search"]
    delays, declared = list(s["delays"]), float(s["declared"])
    fitted = float(c["values"].get("controller.computation_delay", declared))
    i0, i1 = delays.index(declared), delays.index(fitted)
    gains = [1.0 - sse[i1] / sse[i0] if sse[i0] > 0 else 0.0 for sse in s["run_sse"]]
    n = len(gains)
    return {"fitted": fitted, "declared": declared, "passes": bool(c.get("passes")),
            "train_gain": float(c.get("train_gain", 0.0)), "run_best": [float(b) for b in s["run_best"]],
            "run_gain": gains, "agreement": sum(float(b) == fitted for b in s["run_best"]) / n,
            "helped": sum(g > 0 for g in gains) / n}


def line(row):
    """``row``'s dataset and :func:`signature` as one line of text (units: samples of the velocity loop, %)."""
    head = (f"{row['seed']} {'/'.join(row.get('withheld') or ['null'])} {row.get('axis')} "
            f"SNR {row.get('snr', 0):.1f}" + (" (oscillates)" if row.get("oscillation") else ""))
    s = signature(row)
    if s is None:
        return head + ": no delay search recorded"
    n = len(s["run_best"])
    return (f"{head}: fitted {s['fitted']:g} (declared {s['declared']:g}), "
            f"{'passes' if s['passes'] else 'not claimed'}, training gain {100 * s['train_gain']:.1f} %; runs' own "
            f"best {', '.join(f'{b:g}' for b in s['run_best'])}; run gains "
            f"{', '.join(f'{100 * g:+.1f}' for g in s['run_gain'])} %; agreement {round(s['agreement'] * n)}/{n}, "
            f"helped {round(s['helped'] * n)}/{n}")


def main(argv=None):
    """Print one :func:`line` per row of each rows file; the exit status (2 on an unreadable file)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rows", nargs="+", metavar="ROWS.json", help="rows files with the delay search's record")
    a = ap.parse_args(argv)
    files = [read_rows(ap, "ROWS.json", p, keys=("seed", "ranking"), writer="diagnose_dataset.py --json or "
                       "bench_gap_benchmark.py --json") for p in a.rows]
    for data in files:
        for row in data["datasets"]:
            print(line(row))
    return 0


if __name__ == "__main__":
    sys.exit(main())
