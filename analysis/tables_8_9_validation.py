"""Tables 8-9: leave-one-out validation over the five distinct experiments, the competing hypotheses for the
gap between the uncalibrated model and the rig (lead error, force ripple, grating interpolation error, speed
quantization, and every pair), and the sensitivity of the held-out error to each fixed shape.

Every prediction comes from the project's Drake model (drakecreep.studies.table_fluctuation: base run and
unit responses per experiment, the scale reading of the Drake LinearScale; a full simulation checks the
superposition at the fitted amplitudes). Units: mm/s for speeds, % for errors.

Writes out/tables-8-9/validation.md and validation.json.
Run: python analysis/tables_8_9_validation.py [OUT_DIR] [--no-sensitivity]   (about 5-7 min on one core;
the library caches every simulation within the run)
"""

import argparse
import sys
import time

from drakecreep.studies.table_fluctuation import write_validation


def main(argv=None):
    """Write and print the validation of ``argv``'s options; the exit status."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter,
                                 allow_abbrev=False)  # "--no" is refused, not read as --no-sensitivity
    ap.add_argument("out", nargs="?", default="out/tables-8-9", metavar="OUT_DIR",
                    help="output directory (default out/tables-8-9)")
    ap.add_argument("--no-sensitivity", action="store_true", help="skip the sensitivity to each fixed shape")
    a = ap.parse_args(argv)
    start = time.perf_counter()
    v = write_validation(a.out, with_sensitivity=not a.no_sensitivity)
    exps = v["experiments"]
    print(f"{'hypothesis':28s} {'k':>2s} {'in-sample RMS %':>15s} {'held-out mean|%|':>16s} {'max|%|':>7s}  "
          + "  ".join(f"LC{e['load_case']}@{e['feed_mm_s']:g}" for e in exps) + "   AICc    BIC   amplitudes")
    for h in v["hypotheses"]:
        aicc = "   n/a" if h["aicc"] is None else f"{h['aicc']:6.1f}"
        print(f"{h['hypothesis']:28s} {h['k']:2d} {h['in_sample_rms_percent']:15.1f} "
              f"{h['held_out_mean_abs_percent']:16.1f} {h['held_out_max_abs_percent']:7.1f}  "
              + "  ".join(f"{p['held_out_error_percent']:+8.1f}" for p in h["experiments"])
              + f" {aicc} {h['bic']:6.1f}   "
              + ", ".join(f"{k} {a:.3g}" for k, a in h["amplitudes"].items()))
    print("\nrounding noise of the printed values (RMS %):", ", ".join(f"{x:.1f}" for x in v["rounding_noise_percent"]))
    print("\nsignatures (each effect alone, normalized at LC3 1 mm/s):")
    for name, s in v["signatures"].items():
        print(f"  {name:14s}", " ".join(f"{x:6.3f}" for x in s))
    print("\nbest against each, fold by fold (two-sided sign test; 5 folds cannot give p < 0.0625):")
    for d in v["paired"]:
        print(f"  {d['best']} vs {d['against']:28s} wins {d['best_wins']} of {d['folds']}, p = {d['sign_test_p']:.3f}")
    print("\nfull Drake simulation at the in-sample amplitudes (direct - superposed, mm/s):")
    for name, rows in v["verification"].items():
        print(f"  {name:28s}", " ".join(f"{r['difference_mm_s']:+.5f}" for r in rows))
    if v["sensitivity"]:
        print("\nsensitivity: mean held-out error (%) per shape value")
        for r in v["sensitivity"]:
            print(f"  {r['shape']:32s} {r['value']:8.4g} {r['unit']:3s}{'*' if r['nominal'] else ' '} "
                  f"{r['hypothesis']:28s} {r['held_out_mean_abs_percent']:6.1f}")
    print(f"\nwrote {v['paths']['validation_markdown']} and {v['paths']['validation_json']} "
          f"in {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
