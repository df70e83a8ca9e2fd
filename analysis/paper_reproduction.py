"""Tables 8-9 reproduced with the paper_calibrated preset, plus how much the predictions depend on the
two shapes fixed before calibrating (ripple frequency 5 Hz, lead-error period Ph/12).

Writes to out/paper-reproduction/: table8_9.md/.csv, rows.json, fig11/fig12, sensitivity.md.
Run: python analysis/paper_reproduction.py [OUT_DIR]   (about 3-4 minutes on one core)
"""

import argparse
import sys
from pathlib import Path

from drakecreep.studies.paper_reproduction import calibrate, reproduce, write_report
from drakecreep.params import preset, with_value


def main(out="out/paper-reproduction"):
    out = Path(out)
    report = write_report(out, preset("paper_calibrated"), "paper_calibrated")
    print(report["paths"]["markdown"].read_text())
    lead = preset("paper").screw.lead
    variants = [("as calibrated (5 Hz, Ph/12)", {})]
    variants += [(f"ripple {f:g} Hz", {"disturbance.ripple_frequency": f}) for f in (2.0, 10.0)]
    variants += [(f"lead-error period Ph/{n}", {"disturbance.lead_error_period": lead / n}) for n in (6, 24)]
    lines = ["# Sensitivity of the predicted rows to the shapes fixed before calibrating", "",
             "Each variant is recalibrated on rows 4 and 6, then rows 1, 2, 3 (= 5) predicted.", "",
             "| variant | lead error (um) | force ripple (N) | row 1 (%) | row 2 (%) | row 3 (%) | worst predicted (%) |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for name, changes in variants:
        base = preset("paper")
        for path, value in changes.items():
            base = with_value(base, path, value)
        params, info = calibrate(base)
        rows, _ = reproduce(params)
        err = {r["row"]: r["error_vs_experiment_percent"] for r in rows}
        worst = max(abs(err[i]) for i in (1, 2, 3))
        v = info["values"]
        lines.append(f"| {name} | {v['disturbance.lead_error_amplitude'] * 1e6:.3f} | {v['disturbance.force_ripple']:.3f} | "
                     f"{err[1]:+.1f} | {err[2]:+.1f} | {err[3]:+.1f} | {worst:.1f} |")
        print(lines[-1], flush=True)
    (out / "sensitivity.md").write_text("\n".join(lines) + "\n")


def cli(argv=None):
    """Parse ``argv`` and run :func:`main`; the exit status."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", nargs="?", default="out/paper-reproduction", metavar="OUT_DIR",
                    help="output directory (default out/paper-reproduction)")
    main(ap.parse_args(argv).out)
    return 0


if __name__ == "__main__":
    sys.exit(cli())
