"""Loading measured runs for a diagnosis and choosing the training and held-out ones.

(Library side of ``drakecreep diagnose``: the CLI only parses arguments.)
"""

from pathlib import Path

from drakecreep.errors import InputError

__all__ = ["load_runs", "pick"]


def load_runs(data, meta=None, split=True):
    """Runs of a data file: EMPS ``.mat`` (or its role name) or CSV + metadata; one run -> cycles.

    Parameters
    ----------
    data : str or path
        ``estimation`` / ``validation`` (the EMPS files), an EMPS ``.mat`` file, or a measured run
        (CSV, Parquet, HDF5, or ``.mat`` with ``meta``; see ``docs/measured_format.md``).
    meta : str or path, optional
        Metadata YAML of a measured run (default: beside it).
    split : bool
        Split a single-run file into out-and-back cycles (False: the file's runs as they are).

    Returns
    -------
    list of drakecreep.gap.measured.MeasuredRun
    """
    from drakecreep.gap.diagnosis import split_cycles
    from drakecreep.gap.measured import EMPS_FILES, load_emps, load_measured

    if data in EMPS_FILES or (str(data).endswith(".mat") and meta is None):
        md = load_emps(data)
    else:
        if not Path(data).exists():
            raise FileNotFoundError(2, "No such file or directory", str(data))
        md = load_measured(data, meta)
    runs = list(md.runs)
    if split and len(runs) == 1:
        runs = split_cycles(runs[0])
    return runs


def pick(runs, spec, default_parity, option="--train"):
    """Runs selected by a comma list of labels or indices, or by index parity (``default_parity`` 0 or 1);
    errors name the CLI ``option`` the selection came from."""
    if not spec:
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
            raise InputError(option, item, "a run label or index among " + ", ".join(labels))
    return out
