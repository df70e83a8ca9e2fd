"""Convergence of the multibody model's natural frequencies in the number of screw segments N.

For each N the first ``--modes`` flexible modes (full model: fixed joints of Tables 1-2; and with
``--rigid-joints``), the relative change of each mode against the finest N, and the smallest N whose
modes all lie within ``--tolerance`` (default 1 %) of the finest. Prints a Markdown table; writes
``convergence.json`` into ``--out`` (default ``out/multibody_convergence``).

    python analysis/multibody_convergence.py [--segments 4 6 8 12 16 24] [--modes 10] [--rigid-joints]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from drakecreep.multibody import build_multibody, modal_analysis, two_mass_axial_frequency
from drakecreep.params import preset

__all__ = ["study", "main"]


def study(params, segments, num_modes=10, rigid_joints=False):
    """Frequencies (Hz) and labels of the first modes for each N, and the build + analysis time (s)."""
    rows = []
    for n in segments:
        start = time.perf_counter()
        result = modal_analysis(build_multibody(params, n_segments=n, rigid_joints=rigid_joints), num_modes=num_modes)
        rows.append({"n_segments": n, "seconds": time.perf_counter() - start,
                     "frequencies_Hz": [m.frequency for m in result.modes],
                     "labels": [m.label for m in result.modes]})
    finest = rows[-1]["frequencies_Hz"]
    for row in rows:
        row["max_relative_change"] = max(abs(f / g - 1.0) for f, g in zip(row["frequencies_Hz"], finest))
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--segments", type=int, nargs="+", default=[4, 6, 8, 12, 16, 24])
    parser.add_argument("--modes", type=int, default=10)
    parser.add_argument("--rigid-joints", action="store_true")
    parser.add_argument("--tolerance", type=float, default=0.01)
    parser.add_argument("--out", default="out/multibody_convergence")
    args = parser.parse_args(argv)
    params = preset("paper")
    rows = study(params, sorted(args.segments), args.modes, args.rigid_joints)
    finest = rows[-1]
    print(f"paper preset, {'rigid fixed joints' if args.rigid_joints else 'fixed joints of Tables 1-2'}; "
          f"two-mass axial mode {two_mass_axial_frequency(params):.2f} Hz")
    print("| N | " + " | ".join(f"mode {i + 1}" for i in range(len(finest["labels"]))) + " | max change vs N="
          f"{finest['n_segments']} | time (s) |")
    print("|---" * (len(finest["labels"]) + 3) + "|")
    print("| (label) | " + " | ".join(finest["labels"]) + " | | |")
    for row in rows:
        print(f"| {row['n_segments']} | " + " | ".join(f"{f:.2f}" for f in row["frequencies_Hz"])
              + f" | {100 * row['max_relative_change']:.3f} % | {row['seconds']:.2f} |")
    converged = next(r["n_segments"] for r in rows if r["max_relative_change"] <= args.tolerance)
    print(f"smallest N within {100 * args.tolerance:g} % of N={finest['n_segments']}: {converged}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / f"convergence{'_rigid' if args.rigid_joints else ''}.json").write_text(
        json.dumps({"rows": rows, "tolerance": args.tolerance, "converged_n": converged}, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
