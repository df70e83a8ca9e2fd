"""Loading measured runs for a diagnosis and choosing the training and held-out ones.

(Library side of ``drakecreep diagnose``: the CLI only parses arguments.)
"""

import dataclasses
import math
from pathlib import Path

import numpy as np

from drakecreep.errors import InputError, renaming

__all__ = ["load_runs", "pick", "train_test", "split_half_cycles", "split_cycles", "HALF_CYCLE_MIN_TIME",
           "CYCLE_MIN_TIME", "min_samples", "log_rate_notes"]


def _reversals(run):
    """Sample indices where the reference changes direction (speeds below 1 % of the largest are standstill)."""
    v = np.gradient(run.x_ref, run.dt)
    s = np.sign(v) * (np.abs(v) > 0.01 * np.max(np.abs(v)))
    nz = np.flatnonzero(s)
    return [int(c) for c in nz[1:][np.diff(s[nz]) != 0]]


#: shortest part kept by :func:`split_half_cycles` and by :func:`split_cycles` [s]: a duration, not a count of
#: samples (500 and 200 samples at 1 kHz until session 86, which cut a run logged every 4 ms into parts of 2 s)
HALF_CYCLE_MIN_TIME, CYCLE_MIN_TIME = 0.5, 0.2


def min_samples(run, duration):
    """The fewest samples of ``run`` that span ``duration`` seconds (the shortest part a split keeps)."""
    return int(math.ceil(duration / run.dt - 1e-9))


def _cut(run, cuts, duration, sep):
    least = min_samples(run, duration)
    parts = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        if b - a >= least:
            parts.append(dataclasses.replace(run.slice(a, b), label=f"{run.label}{sep}{len(parts)}"))
    return parts


def split_half_cycles(run, min_time=HALF_CYCLE_MIN_TIME):
    """Parts of ``run`` between reversals of the reference (label ``<label>@<i>``), at least ``min_time`` seconds
    long (:func:`min_samples`)."""
    return _cut(run, [0] + _reversals(run) + [run.n], min_time, "@")


def split_cycles(run, cycles_per_run=1, min_time=CYCLE_MIN_TIME):
    """Split a run at every second change of direction of the reference (one out-and-back cycle per part).

    Parameters
    ----------
    run : drakecreep.gap.measured.MeasuredRun
    cycles_per_run : int
        Cycles per part.
    min_time : float
        Parts shorter than this [s] are dropped (:func:`min_samples`).

    Returns
    -------
    list of MeasuredRun
        Labelled ``<label>#<i>``.
    """
    return _cut(run, [0] + _reversals(run)[1::2 * cycles_per_run] + [run.n], min_time, "#")


def log_rate_notes(data, logged, ticked):
    """Lines saying how runs logged at another rate than their controller's tick are read: ``logged`` as the file
    holds them, ``ticked`` after :func:`~drakecreep.gap.measured.on_controller_ticks` (one line per rate and kind).

    A wrong ``controller.sample_time`` that is a whole fraction or multiple of the log's is read so too, so the
    reading is said rather than done silently (a 1 ms log declared with 0.25 ms replays a loop four times faster).
    """
    from drakecreep.gap.measured import controller_ticks

    lines = []
    for raw, run in zip(logged, ticked):
        ctrl = raw.meta.controller
        try:
            every = controller_ticks(run)
        except InputError:  # no whole ratio: the replay's check refuses the run, named by its file (not said here)
            continue
        if run is not raw:
            line = (f"{data}: logged every {raw.dt:g} s, {int(round(run.dt / raw.dt))} samples per tick of "
                    f"controller.sample_time {ctrl.sample_time:g} s: cut to its ticks, where the held u changes")
        elif every > 1:
            line = (f"{data}: logged every {run.dt:g} s, every {every} ticks of controller.sample_time "
                    f"{ctrl.sample_time:g} s: the controller is replayed on its tick, the reference linear between "
                    "logged samples")
        else:
            continue
        if line not in lines:
            lines.append(line)
    return lines


def load_runs(data, meta=None, split=True, notes=None):
    """Runs of a data file: EMPS ``.mat`` (or its role name) or CSV + metadata; one run -> cycles.

    Parameters
    ----------
    data : str or path
        ``estimation`` / ``validation`` (the EMPS files), an EMPS ``.mat`` file, or a measured run
        (CSV, Parquet, HDF5, or ``.mat`` with ``meta``; see ``docs/measured_format.md``).
    meta : str or path, optional
        Metadata YAML of a measured run (default: beside it); none with ``estimation`` / ``validation``.
    split : bool or str
        Split a single-run file into out-and-back cycles (True), into the parts between reversals of the
        reference (``"half"``, :func:`split_half_cycles`), or not at all (False).
    notes : list, optional
        Receives :func:`log_rate_notes` of the file's runs.

    Returns
    -------
    list of drakecreep.gap.measured.MeasuredRun
        A ``p_p_cascade`` run logged several times per controller tick is cut to its ticks
        (:func:`~drakecreep.gap.measured.on_controller_ticks`).
    """
    from drakecreep.gap.measured import EMPS_FILES, load_emps, load_measured, on_controller_ticks

    if data in EMPS_FILES and meta is not None:  # the benchmark's own metadata: a meta file was ignored unsaid
        raise InputError("meta", str(meta), f"no metadata with the EMPS benchmark's {data} file (its controller, "
                         "gains and units are the benchmark's; a measured run's metadata goes with its data file)")
    if data in EMPS_FILES or (str(data).endswith(".mat") and meta is None):
        try:
            md = load_emps(data)
        except InputError as err:
            beside = [p for p in (Path(data).with_suffix(".yaml"), Path(data).with_suffix(".yml")) if p.is_file()]
            if data in EMPS_FILES or not beside or not str(err.field).endswith(": variables"):
                raise
            # a measured run's .mat with its metadata beside it was told of the EMPS variables alone
            raise InputError(err.field, err.value, f"{err.allowed}; or a measured run's signals, with its metadata "
                             f"named (diagnose --meta {beside[0]}: without it a .mat is read as an EMPS file)") from None
    else:
        if not Path(data).exists():
            raise FileNotFoundError(2, "No such file or directory", str(data))
        md = load_measured(data, meta)
    # a log taken several times a controller tick: at its ticks (a refusal names the file, as load_measured's do)
    runs = [renaming(lambda field: f"{data}: {field}", on_controller_ticks, r) for r in md.runs]
    if notes is not None:
        notes.extend(log_rate_notes(data, md.runs, runs))
    if split == "half" and len(runs) == 1:
        runs = split_half_cycles(runs[0])
    elif split and len(runs) == 1:
        runs = split_cycles(runs[0])
    return runs


def train_test(runs, train_spec=None, test_spec=None, pairs=False):
    """Training and held-out runs from the ``--train`` / ``--test`` selections (:func:`pick`).

    Without either selection: even / odd indices (or pairs of them, ``pairs``); three runs (or parts) are split
    1 / 2 instead (the first trains, the other two are held out), since a diagnosis needs two held-out runs. With
    one selection only, the other is every run it does not name.
    """
    if not train_spec and not test_spec and len(runs) == 3:
        return [runs[0]], list(runs[1:])
    train = pick(runs, train_spec, 0, "--train", pairs=pairs) if train_spec or not test_spec else None
    test = pick(runs, test_spec, 1, "--test", pairs=pairs) if test_spec or not train_spec else None
    if train is None:
        train = [r for r in runs if all(r is not t for t in test)]
    if test is None:
        test = [r for r in runs if all(r is not t for t in train)]
    return train, test


def pick(runs, spec, default_parity, option="--train", pairs=False):
    """Runs selected by a comma list of labels or indices, or by index parity (``default_parity`` 0 or 1);
    errors name the CLI ``option`` the selection came from. A label that holds a comma is named by its index
    (the error says which). ``pairs``: the default alternates pairs of runs
    (indices 0, 1, 4, 5, ... and 2, 3, 6, 7, ...: out-and-back half cycles, so both sets move both ways)."""
    if not spec:
        if pairs:
            return [r for i, r in enumerate(runs) if (i // 2) % 2 == default_parity]
        return [r for i, r in enumerate(runs) if i % 2 == default_parity]
    out = []
    labels = [r.label for r in runs]
    for item in spec.split(","):
        item = item.strip()
        if item in labels:
            out.append(runs[labels.index(item)])
        elif item.isascii() and item.isdigit() and len(item) < 10 and int(item) < len(runs):
            out.append(runs[int(item)])
        else:
            commas = [f"{i} for {lab!r}" for i, lab in enumerate(labels) if "," in lab]
            raise InputError(option, item, "a run label or index among " + ", ".join(labels)
                             + (f" (a label with a comma by its index: {', '.join(commas)})" if commas else ""))
        if any(out[-1] is r for r in out[:-1]):  # a run twice would count as two (two held-out runs from one)
            raise InputError(option, spec, f"each run once ({item} names a run given before)")
    return out
