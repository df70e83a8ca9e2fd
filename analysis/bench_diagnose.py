"""Time of the EMPS gap diagnosis on the Drake model (issue 16: "the diagnosis in <= 60 s").

Times :func:`drakecreep.gap.drake_diagnosis.diagnose_drake` (what ``drakecreep diagnose`` runs on
p_p_cascade data) on the estimation file split as in ``analysis/emps_drake.py`` (pairs of half cycles,
4 training / 4 held-out parts) and, in the same process, a baseline: one closed-loop replay of the whole
24841-sample estimation file through the error-controlled Drake diagram (:class:`DrakeReplay`, the replay
before the sampled fast path) with the IDIM model. The ratio is robust to a busy machine; the absolute
time is the one the issue asks for.

With ``--validate`` it then refits the augmented model on the whole estimation file and replays the
validation file once, parameters fixed (``analysis/emps_drake.py``'s last step): force error target < 6 %.

Run from the repository root: ``PYTHONPATH=. python analysis/bench_diagnose.py [--validate]``
"""

import argparse
import importlib.util
import time
from pathlib import Path

from drakecreep.gap.drake_diagnosis import diagnose_drake
from drakecreep.gap.drake_replay import DrakeReplay
from drakecreep.gap.identify import idim_start
from drakecreep.gap.measured import load_emps


def _study():
    spec = importlib.util.spec_from_file_location("emps_drake", Path(__file__).with_name("emps_drake.py"))
    study = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(study)
    return study


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--validate", action="store_true", help="also refit on the whole estimation file and replay "
                    "the validation file once")
    args = ap.parse_args()
    study = _study()
    est = load_emps("estimation").run()
    parts = study.split_half_cycles(est)
    train = [p for i, p in enumerate(parts) if i % 4 in (0, 1)]
    held = [p for i, p in enumerate(parts) if i % 4 in (2, 3)]
    start = time.perf_counter()
    DrakeReplay(est).simulate(dict(idim_start([est]).parameters, regularization_velocity=1e-3))
    baseline = time.perf_counter() - start
    start = time.perf_counter()
    diag = diagnose_drake(train, held, progress=lambda line: print(f"  [{time.perf_counter() - start:5.0f} s] {line}",
                                                                   flush=True))
    seconds = time.perf_counter() - start
    print("\n".join(diag.summary()))
    print(f"EMPS diagnosis on the Drake model: {seconds:.1f} s wall (target 60 s)")
    print(f"baseline, one error-controlled DrakeReplay of the 24841-sample estimation file: {baseline:.2f} s "
          f"-> diagnosis = {seconds / baseline:.1f} x baseline")
    print("claimed: " + (" + ".join(diag.claimed) or "nothing"))
    if args.validate:
        study.validate(diag, est)


if __name__ == "__main__":
    main()
