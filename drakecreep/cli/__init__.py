"""The ``drakecreep`` command line: parses arguments and calls the library, nothing more.

Each subcommand lives in its own module of this package and exposes

* ``add_parser(subparsers)`` -- registers the subcommand and its options;
* ``run(args) -> int`` -- calls the library and prints; returns the exit code.

User errors (:class:`drakecreep.errors.DrakecreepError`, bad files, bad options) print one line on stderr
and exit with code 2, never a traceback.
"""

import argparse
import importlib
import re
import textwrap
import os
import sys

from drakecreep import __version__
from drakecreep.errors import DrakecreepError

__all__ = ["main", "build_parser", "COMMANDS"]

#: Subcommand modules, in the order ``--help`` lists them.
COMMANDS = [
    "simulate",
    "params",
    "diagram",
    "critical",
    "hertz",
    "modal", "modes",
    "margins", "tune", "report",
    "sweep", "uncertainty",
    "emps",
    "reproduce_paper", "compensate",
    "diagnose", "gap_benchmark",
]


def plain(text):
    """Help text without reStructuredText markup (``code``, :func:`name`, :class:`~a.b.C`)."""
    text = re.sub(r":[a-z]+:`~?([^`]+)`", lambda m: m.group(1).rpartition(".")[2] if m.group(0).count("~") else m.group(1), text)
    return text.replace("``", "'").replace("`", "'")


class _Formatter(argparse.HelpFormatter):
    """Wraps the description paragraph by paragraph; strips reStructuredText markup from every help text."""

    def _fill_text(self, text, width, indent):
        paragraphs = [" ".join(p.split()) for p in plain(text).split("\n\n")]
        return "\n\n".join(textwrap.fill(p, width, initial_indent=indent, subsequent_indent=indent)
                             for p in paragraphs if p)

    def _expand_help(self, action):
        return plain(super()._expand_help(action))


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line and exit code 2; help without reStructuredText markup."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", _Formatter)
        super().__init__(*args, **kwargs)

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser():
    """Build the top-level parser with every registered subcommand."""
    parser = _Parser(
        prog="drakecreep",
        description="Ball-screw feed drive in Drake: simulate creep, analyse servo loops, diagnose sim-to-real gaps.",
    )
    parser.add_argument("--version", action="version", version=f"drakecreep {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMANDS:
        module = importlib.import_module(f"drakecreep.cli.{name}")
        module.add_parser(sub)
    return parser


def main(argv=None):
    """Entry point of the ``drakecreep`` console script."""
    os.environ.setdefault("MPLBACKEND", "Agg")  # the CLI writes plots to files, never to a screen
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except DrakecreepError as err:
        print(f"drakecreep {args.command}: error: {err}", file=sys.stderr)
        return 2
    except (FileNotFoundError, IsADirectoryError, PermissionError) as err:
        print(f"drakecreep {args.command}: error: {err.strerror}: {err.filename}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"drakecreep {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
