"""The command line the development-seed studies share: ``--shard K/N --json ROWS`` runs this process's share of
the datasets, ``--score ROWS...`` only scores stored rows."""

import argparse
import sys


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
