"""EMPS benchmark reference results beside the published ones: the IDIM-LS parameters and fit error, the
cross-test score on the validation set (fixed parameters), and the rigid model's closed-loop replay errors.

Prints the Markdown and writes it to ``--out`` (default ``out/emps_reference/emps_reference.md``).

    python analysis/emps_reference.py [--data DIR] [--out DIR]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from drakecreep.gap.emps import reference_results, to_markdown

__all__ = ["main"]


def main(argv=None):
    """Compute, print and write the tables."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", help="folder of DATA_EMPS.mat and DATA_EMPS_PULSES.mat "
                                       "(default: the files shipped in drakecreep/data/emps)")
    parser.add_argument("--out", default="out/emps_reference", help="output folder")
    args = parser.parse_args(argv)
    text = to_markdown(reference_results(args.data))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "emps_reference.md").write_text(text)
    print(text)
    print(f"written: {out / 'emps_reference.md'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
