"""Spent held-out datasets of a saturating drive, diagnosed again with the product path: one row each.

Seeds of held-out runs already scored and looked into (never a run's own seeds before it is scored). The
heavily saturated drives of runs 10-23 (SNR 27-84) were missed or claimed as another effect, and the true
effect's own fit made the audit replay worse (45010001: 80 % -> 299 %). The cause was the closed-loop start:
the nominal's friction shifted by what the candidate moved it on inverse dynamics, when the saturation had
biased the nominal itself (docs/gap_benchmark.md, 3ah). This script reruns ``benchmark.evaluate`` on such
datasets, and on cable carriers and nulls where the candidate's fit was far off the same way, and writes the
rows as the benchmark does (``--score`` of ``analysis/bench_gap_benchmark.py`` reads them).

Usage: ``PYTHONPATH=. python analysis/drive_saturation_start_study.py OUT.json SEED:WITHHELD:AXIS [...]``
(``WITHHELD`` is ``null`` or an effect, ``AXIS`` ``rigid`` or ``flexible``; e.g.
``21010002:drive_saturation:flexible``).
The rows of session 39 are in ``analysis/drive_saturation_start_dev.json``; it reruns any spent dataset, and the
Stribeck rows of session 41 (the start floor and the Stribeck's own start, docs/gap_benchmark.md, 3aj) are in
``analysis/stribeck_start_dev.json``.
"""

import json
import sys
import time

from drakecreep.files import write_text
from drakecreep.gap import benchmark
from study_cli import out_and_specs


def main(argv=None):
    """Rerun each dataset of ``argv`` (every spec checked first) and write the rows; the exit status."""
    out, specs = out_and_specs(__doc__, argv)
    rows = []
    for seed, withheld, axis in specs:
        t0 = time.perf_counter()
        ds = benchmark.generate_dataset(seed, withheld=withheld, kind="p_p_cascade", axis=axis)
        row = benchmark.evaluate(ds)
        rows.append(row)
        print(f"{seed} {'+'.join(withheld) or 'null'} {axis}: SNR {row['snr']:.1f}, claimed {row['claimed']}, "
              f"audit shrink {row['audit_shrink']:.2f} (true fit {row['true_shrink']}), "
              f"{time.perf_counter() - t0:.0f} s", flush=True)
        write_text(out, json.dumps({"note": "spent held-out datasets rerun as development (benchmark.evaluate)",
                                    "datasets": rows}, indent=1, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())
