"""The command lines the development-seed studies share: ``--shard K/N --json ROWS`` runs this process's share of
the datasets, ``--score ROWS...`` only scores stored rows (:func:`shard_main`); ``OUT.json SEED:WITHHELD:AXIS...``
names spent datasets (:func:`out_and_specs`), or ``OUT.json SEED:EFFECT[:AXIS]...`` a study's own cases
(:func:`out_and_cases`, :func:`case_type`)."""

import argparse
import json
import sys

from drakecreep.errors import InputError, name_list
from drakecreep.gap import benchmark


def read_rows(ap, option, path, keys=("seed",), writer="--json"):
    """The parsed rows file ``path`` given to ``option`` (what ``writer``, a ``--json`` of ``bench_gap_benchmark.py``,
    writes), or one line of ``ap.error`` naming what is wrong with it (exit 2): unreadable, not JSON, or rows
    without ``keys``."""
    allowed = f"allowed: a rows file written by {writer}"
    try:
        with open(path) as fh:
            data = json.load(fh)
    except OSError as err:
        ap.error(f"{option}: cannot read {path!r} ({err.strerror}); {allowed}")
    except ValueError as err:
        ap.error(f"{option}: {path!r} is not JSON ({err}); {allowed}")
    if not isinstance(data, dict) or not isinstance(data.get("datasets"), list) \
            or not all(isinstance(r, dict) and all(k in r for k in keys) for r in data["datasets"]):
        ap.error(f"{option}: {path!r} has no list of dataset rows with {', '.join(keys)}; {allowed}")
    return data


def unique_rows(ap, paths, keys=("seed",)):
    """The dataset rows of the rows files ``paths`` (a positional ``rows`` argument of ``ap``), each row once: a
    resumed shard copies its rows whole into its new file, while one seed can carry several different rows (several
    effects drawn on it, several params files, another code), each a diagnosis of its own. A file that cannot be
    read, or whose rows lack ``keys``, is one line of ``ap.error`` (exit 2)."""
    seen, rows = set(), []
    for path in paths:
        try:
            with open(path, encoding="utf-8") as f:
                part = list(json.load(f)["datasets"])
            if not all(isinstance(r, dict) and all(k in r for k in keys) for r in part):
                raise ValueError(f"a dataset without {' or '.join(keys)}")
        except (OSError, ValueError, KeyError, TypeError) as e:
            why = e.strerror if isinstance(e, OSError) else f"no {e}" if isinstance(e, KeyError) else str(e)
            ap.error(f"rows: got {path!r} ({why}); allowed: a JSON file of gap-benchmark rows (a 'datasets' list)")
        for r in part:
            key = json.dumps(r, sort_keys=True)
            if key not in seen:
                seen.add(key)
                rows.append(r)
    return rows


def drakecreep_uncertain(ap, text, option="--uncertain"):
    """The comma-separated fields ``text`` of ``option`` as the ``drakecreep`` kind's uncertain fields
    (:func:`drakecreep.gap.benchmark.check_uncertain`), or one line of ``ap.error`` (exit 2); None stays None."""
    if text is None:
        return None
    try:
        return benchmark.check_uncertain(("drakecreep",), name_list(text.split(","), option))
    except InputError as e:
        ap.error(str(e))


def shard_main(description, study, score, argv=None):
    """Parse ``argv`` and call ``study(k, n, path)`` or ``score(paths)``; the exit status (2 on a bad option, with
    one line naming it)."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--shard", default="0/1", help="K/N: this process's share of the datasets")
    ap.add_argument("--json", help="rows file to write")
    ap.add_argument("--score", nargs="+", metavar="JSON", help="score rows files instead of running")
    a = ap.parse_args(argv)
    if a.score:
        score(a.score)
        return 0
    try:
        k, n = (int(x) for x in a.shard.split("/"))
        if not 0 <= k < n:
            raise ValueError
    except ValueError:
        print(f"--shard: got {a.shard!r}; allowed: K/N with 0 <= K < N", file=sys.stderr)
        return 2
    if not a.json:
        print("--json: missing; allowed: a path for the rows", file=sys.stderr)
        return 2
    study(k, n, a.json)
    return 0


def _out_parser(description, metavar, help, type=None):
    """A parser of ``OUT.json`` and one or more datasets named ``metavar`` (read with ``type``)."""
    ap = argparse.ArgumentParser(description=description, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", metavar="OUT.json", help="rows file, rewritten after each dataset")
    ap.add_argument("datasets", nargs="+", type=type, metavar=metavar, help=help)
    return ap


def out_and_specs(description, argv=None):
    """``(out, specs)`` of ``OUT.json SEED:WITHHELD:AXIS [...]``, each spec read by
    :func:`drakecreep.gap.benchmark.dataset_spec` before any work; a bad one exits 2 with its line."""
    ap = _out_parser(description, "SEED:WITHHELD:AXIS", "a spent dataset: WITHHELD null or an effect, AXIS rigid or "
                     "flexible")
    a = ap.parse_args(argv)
    try:
        return a.out, [benchmark.dataset_spec(d) for d in a.datasets]
    except InputError as e:
        ap.exit(2, f"{e}\n")


def out_and_cases(description, case, metavar, help, argv=None):
    """``(out, cases)`` of ``OUT.json CASE [...]``, each case read by ``case`` (:func:`case_type`) before any work;
    a bad one exits 2 with its line (argparse's)."""
    a = _out_parser(description, metavar, help, type=case).parse_args(argv)
    return a.out, a.datasets


def dev_spec(text):
    """An argparse ``type`` reading ``SEED:WITHHELD:AXIS`` (:func:`drakecreep.gap.benchmark.dataset_spec`) into
    ``(seed, withheld, axis)``, a development seed only (below ``HELDOUT_SEEDS``: those are spent in pre-registered
    runs alone)."""
    try:
        seed, withheld, axis = benchmark.dataset_spec(text)
    except InputError as e:
        raise argparse.ArgumentTypeError(str(e)) from None
    if seed >= benchmark.HELDOUT_SEEDS:
        raise argparse.ArgumentTypeError(f"seed: got {seed}; allowed: a development seed below "
                                         f"{benchmark.HELDOUT_SEEDS}")
    return seed, withheld, axis


def case_type(effects, axis, example):
    """An argparse ``type`` reading ``SEED:EFFECT`` (``axis`` "none"), ``SEED:EFFECT:AXIS`` ("required") or
    ``SEED:EFFECT[:AXIS]`` ("optional") into a tuple of its texts (a left-out axis None), ``EFFECT`` one of
    ``effects``, ``SEED`` an integer >= 0, ``AXIS`` one of the truth's axes; ``example`` shows the form."""
    counts = {"none": (2,), "required": (3,), "optional": (2, 3)}[axis]

    def case(text):
        parts = text.split(":")
        fields = (parts + [None])[:3] if len(parts) in counts else [None, None, None]
        seed, effect, ax = fields
        checks = ((len(parts) in counts, f"the form of {example}"),
                  (seed is not None and seed.isdigit(), "SEED an integer >= 0"),
                  (effect in effects, "EFFECT one of " + ", ".join(effects)),
                  (ax is None or ax in benchmark.T.AXES, "AXIS one of " + ", ".join(benchmark.T.AXES)))
        for ok, allowed in checks:
            if not ok:
                raise argparse.ArgumentTypeError(f"got {text!r}; allowed: {allowed}")
        return (seed, effect) if axis == "none" else (seed, effect, ax)
    return case


def seed_list(text):
    """argparse type of a list of seeds (``--skip-seeds``, ``--seeds``): comma-separated seeds or ranges ``a-b``
    (inclusive) as a tuple of int."""
    seeds = []
    for item in text.split(","):
        lo, _, hi = item.strip().partition("-")
        try:
            first, last = int(lo), int(hi or lo)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{item!r} is no seed or range of seeds (e.g. 114000-114003)") from None
        if not 0 <= first <= last or last - first > 100000:
            raise argparse.ArgumentTypeError(f"{item!r}: seeds >= 0, first <= last, at most 100000 in a range")
        seeds += range(first, last + 1)
    return tuple(seeds)
