"""Friction compensation on the encoder speed at the loop rate against the ideal continuous tachometer (issue 15).

Runs :func:`drakecreep.studies.compensation.evaluate` twice on one preset, with
``compensation.speed_source: encoder`` (the default: compensators at the velocity-loop rate on the count
difference, output held and delayed like the command) and ``ideal`` (continuous, true motor speed), and prints
one Markdown table: per method, load case and feed, the speed fluctuation (mm/s) and its ratio to no
compensation under each source.

Run: python analysis/compensation_speed_source.py [PRESET] [--feeds 0.05,0.1,0.2] [--load-cases 1,2,3] [--delay N]
     python analysis/compensation_speed_source.py --from DIR_ENCODER DIR_IDEAL   (rows.json of two
     ``drakecreep compensate --speed-source ... --out DIR`` runs)
"""

import argparse
import json
from pathlib import Path

from drakecreep.params import preset, with_value
from drakecreep.studies.compensation import DEFAULT_METHODS, evaluate

SOURCES = ("encoder", "ideal")


def rows_for(params, source, feeds, load_cases, duration, workers):
    """The study's rows with ``compensation.speed_source = source``."""
    return evaluate(with_value(params, "compensation.speed_source", source), DEFAULT_METHODS, feeds, load_cases,
                    duration=duration, workers=workers)


def table(by_source):
    """Markdown: one line per (method, load case, feed), fluctuation and ratio to none per source."""
    index = {s: {(r["label"], r["load_case"], r["feed_mm_s"]): r for r in rows} for s, rows in by_source.items()}
    keys = sorted(index[SOURCES[0]], key=lambda k: (DEFAULT_METHODS.index(k[0]) if k[0] in DEFAULT_METHODS else 99,
                                                     k[1], k[2]))
    head = "| method | load | feed (mm/s) | " + " | ".join(
        f"{s}: fluct. (mm/s) | {s}: x none | {s}: creep" for s in SOURCES) + " |"
    lines = [head, "|" + " --- |" * (3 + 3 * len(SOURCES))]
    unconverged = []
    for key in keys:
        cells = []
        for s in SOURCES:
            r = index[s].get(key)
            if r is None:
                cells += ["-", "-", "-"]
                continue
            ratio = r.get("fluctuation_vs_none", float("nan"))
            mark = "" if r.get("converged") in (True, None) else " (u)"
            if mark:
                unconverged.append((s,) + key)
            cells += [f"{r['max_fluctuation_mm_s']:.3g}{mark}", "" if key[0] == "none" else f"{ratio:.2g}",
                      "yes" if r["creep"] else "no"]
        lines.append(f"| {key[0]} | {key[1]} | {key[2]:g} | " + " | ".join(cells) + " |")
    lines.append("")
    lines.append(f"(u): the run's convergence check disagreed (metrics.converged false): {len(unconverged)} rows")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("preset", nargs="?", default="paper")
    ap.add_argument("--feeds", default="0.05,0.1,0.2")
    ap.add_argument("--load-cases", default="1,2,3")
    ap.add_argument("--duration", type=float, default=2.0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--delay", type=float, default=None, help="controller.computation_delay (default: the preset's)")
    ap.add_argument("--from", dest="dirs", nargs=2, metavar=("DIR_ENCODER", "DIR_IDEAL"))
    a = ap.parse_args(argv)
    if a.dirs:
        by_source = {s: json.loads((Path(d) / "rows.json").read_text())["rows"] for s, d in zip(SOURCES, a.dirs)}
    else:
        params = preset(a.preset)
        if a.delay is not None:
            params = with_value(params, "controller.computation_delay", a.delay)
        feeds = [float(x) for x in a.feeds.split(",")]
        loads = [int(x) for x in a.load_cases.split(",")]
        by_source = {s: rows_for(params, s, feeds, loads, a.duration, a.workers) for s in SOURCES}
    print(table(by_source))


if __name__ == "__main__":
    main()
