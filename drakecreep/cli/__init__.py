"""The ``drakecreep`` command line: parses arguments and calls the library, nothing more.

Each subcommand lives in its own module of this package and exposes

* ``add_parser(subparsers)`` -- registers the subcommand and its options;
* ``run(args) -> int`` -- calls the library and prints; returns the exit code.

User errors (:class:`drakecreep.errors.DrakecreepError`, bad files, bad options) print one line on stderr
and exit with code 2, never a traceback. Anything unexpected (a bug, a full disk) prints one line naming
the error and pointing to ``--debug`` (which shows the traceback) and exits with code 1; Ctrl-C exits 130. A
SIGTERM (``kill``, ``timeout``, a job scheduler) stops as a Ctrl-C does, keeping what was computed, and exits 143.
"""

import argparse
import errno
import importlib
import re
import signal
import textwrap
import os
import sys
import threading
import time
import traceback

from drakecreep import __version__
from drakecreep.errors import DrakecreepError, Terminated

__all__ = ["main", "build_parser", "COMMANDS", "HEARTBEAT", "HEARTBEAT_AFTER", "plain"]

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


#: Commands that can take more than ~2 s and report no progress of their own: an elapsed-time bar on stderr
#: (on a terminal, or with DRAKECREEP_PROGRESS=1).
HEARTBEAT = ("report", "compensate", "reproduce-paper", "margins", "tune", "critical", "modal", "emps", "simulate")
#: seconds a job runs before its heartbeat shows: shorter jobs stay silent
HEARTBEAT_AFTER = 2.0


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


_NUMBER = r"(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|inf(?:inity)?|nan"
#: what argparse takes for a negative number (an option's value, not an option): argparse's own matcher knows no
#: exponent (in Python 3.11), so 'modes --table-position -1e-3' ended in 'expected one argument' while -0.001 ran;
#: also -inf and -nan (the option's type names them) and comma lists starting with one ('--feeds -1,2')
_NEGATIVE_NUMBER = re.compile(rf"^-(?:{_NUMBER})(?:,\s*[-+]?(?:{_NUMBER})?)*$", re.IGNORECASE)


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line and exit code 2; help without reStructuredText markup.

    Options are spelled out: an abbreviation is an error, not a guess (``--n 0`` would otherwise be read as
    ``--no-progress`` followed by a stray ``0``, and a new option could silently change what an old
    abbreviation means).
    """

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", _Formatter)
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER  # before any option is added (argparse checks them with it)

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {_refusal(message)}\n")


#: argparse's own refusals of an option's value, and what the option allows
_ARGPARSE_REFUSALS = [
    (re.compile(r"invalid int value: (?P<got>.*)"), lambda m: "an integer"),
    (re.compile(r"invalid float value: (?P<got>.*)"), lambda m: "a number"),
    (re.compile(r"invalid choice: (?P<got>.*?) \(choose from (?P<allowed>.*)\)"),
     lambda m: "one of " + m.group("allowed").replace("'", "")),
    (re.compile(r"expected (?P<n>.+?) arguments?()(?P<got>)"),
     lambda m: f"{m.group('n')} value{'' if m.group('n').endswith('one') else 's'} after the option"),
]


def _refusal(message):
    """argparse's error ``message`` in the refusals' own form, ``OPTION: got VALUE; allowed: WHAT``.

    The types of :mod:`drakecreep.cli._common` already say ``got ...; allowed: ...``: only the word ``argument``
    argparse puts before the option goes. argparse's own refusals of a value (an int or float it cannot read, a
    choice not listed, an option without its value) are put in that form; any other message is left as it is.
    """
    if not message.startswith("argument ") or ": " not in message:
        return message
    option, _, rest = message[len("argument "):].partition(": ")
    if rest.startswith("got ") and "; allowed: " in rest:
        return f"{option}: {rest}"
    for pattern, allowed in _ARGPARSE_REFUSALS:
        m = pattern.fullmatch(rest)
        if m:
            got = m.group("got") or "nothing"
            return f"{option}: got {got}; allowed: {allowed(m)}"
    return message


def _add_common(parser, suppress):
    """``-q/--quiet`` and ``-v/--verbose``, before or after the command."""
    default = argparse.SUPPRESS if suppress else None
    parser.add_argument("-q", "--quiet", action="store_true", default=default or False,
                        help="no progress on stderr (results and errors only)")
    parser.add_argument("-v", "--verbose", action="count", default=default or 0,
                        help="more detail on stderr: INFO logging; -vv DEBUG logging and tracebacks (as --debug)")


def _heartbeat(command):
    """Start an elapsed-time tqdm bar on stderr; returns a function that stops it."""
    from tqdm import tqdm

    stop = threading.Event()
    bar = tqdm(desc=f"drakecreep {command}", bar_format="{desc}: {elapsed} elapsed", file=sys.stderr,
               delay=HEARTBEAT_AFTER, mininterval=0.5)

    start = time.monotonic()

    def tick():
        while not stop.wait(0.5):
            if time.monotonic() - start >= HEARTBEAT_AFTER:  # short jobs stay silent
                bar.refresh()

    thread = threading.Thread(target=tick, daemon=True)
    thread.start()

    def done():
        stop.set()
        thread.join()
        bar.close()

    return done


def _terminate(signum, frame):
    raise Terminated()


def _on_sigterm():
    """Handle ``SIGTERM`` as a Ctrl-C while a command runs (:class:`~drakecreep.errors.Terminated`); returns the
    handler it replaced (None where signals cannot be set: not the main thread)."""
    if threading.current_thread() is not threading.main_thread():
        return None
    return signal.signal(signal.SIGTERM, _terminate)


def build_parser():
    """Build the top-level parser with every registered subcommand."""
    parser = _Parser(
        prog="drakecreep",
        description="Ball-screw feed drive in Drake: simulate creep, analyse servo loops, diagnose sim-to-real gaps.",
    )
    parser.add_argument("--version", action="version", version=f"drakecreep {__version__}")
    _add_common(parser, suppress=False)
    parser.add_argument("--debug", action="store_true", help="show the full traceback of an unexpected error")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = False  # main names an unknown option before the missing command
    for name in COMMANDS:
        module = importlib.import_module(f"drakecreep.cli.{name}")
        _add_common(module.add_parser(sub), suppress=True)
    parser.commands = sub.choices  # name -> subcommand parser: its own errors name it (main)
    return parser


def main(argv=None):
    """Entry point of the ``drakecreep`` console script."""
    os.environ.setdefault("MPLBACKEND", "Agg")  # the CLI writes plots to files, never to a screen
    parser = build_parser()
    args, extra = parser.parse_known_args(argv)
    if args.command is None:  # an unknown option before no command is named first
        parser.error(f"unrecognized arguments: {' '.join(extra)} (drakecreep --help lists the commands and the "
                     "options)" if extra else "the following arguments are required: COMMAND")
    if extra:  # the command's own parser says it, with its name and where its options are listed
        parser.commands[args.command].error(f"unrecognized arguments: {' '.join(extra)} "
                                            f"(drakecreep {args.command} --help lists the options)")
    if args.verbose:
        import logging

        logging.basicConfig(level=logging.DEBUG if args.verbose > 1 else logging.INFO, stream=sys.stderr)
    saved = os.environ.get("TQDM_DISABLE")
    if args.quiet:
        os.environ["TQDM_DISABLE"] = "1"  # every tqdm bar of the library (tqdm >= 4.66), also in worker processes
    # the elapsed-time bar only on a terminal (logs and pipes keep one line per message), or when forced
    show = sys.stderr.isatty() or os.environ.get("DRAKECREEP_PROGRESS") == "1"
    stop = _heartbeat(args.command) if args.command in HEARTBEAT and show and not args.quiet else None
    debug = getattr(args, "debug", False) or args.verbose > 1
    prefix = f"drakecreep {args.command}"
    previous = _on_sigterm()
    try:
        _check_no_empty_values(parser, args)
        _check_no_repeated_options(parser, args, sys.argv[1:] if argv is None else argv)
        return int(args.func(args) or 0)
    except DrakecreepError as err:
        _debug_traceback(debug)
        # the whole line: an InputError bounds its own parts (value 120, allowed 600 characters), and a list of
        # what is allowed cut short hides the right answer (the fitted fields' list is 450 characters)
        print(f"{prefix}: error: {_one_line(err, limit=1000)}", file=sys.stderr)
        return 2
    except (FileNotFoundError, IsADirectoryError, NotADirectoryError, PermissionError) as err:
        _debug_traceback(debug)
        print(f"{prefix}: error: {err.strerror}: {_one_line(err.filename)}", file=sys.stderr)
        return 2
    except OSError as err:
        _debug_traceback(debug)
        if err.filename is not None and err.errno in _PATH_ERRNOS:  # a bad path the user gave
            print(f"{prefix}: error: {err.strerror}: {_one_line(err.filename)}", file=sys.stderr)
            return 2
        hint = "" if debug else " (run again with --debug for the traceback)"
        print(f"{prefix}: internal error: {type(err).__name__}: {_one_line(err.strerror or err)}"
              f"{': ' + _one_line(err.filename) if err.filename else ''}{hint}", file=sys.stderr)
        return 1
    except KeyboardInterrupt as err:
        if isinstance(err, Terminated):
            print(f"{prefix}: terminated (SIGTERM)", file=sys.stderr)
            return 143
        print(f"{prefix}: interrupted", file=sys.stderr)
        return 130
    except Exception as err:  # noqa: BLE001 - the one top-level guard: one line, the traceback on --debug
        _debug_traceback(debug)
        what = _one_line(err)
        hint = "" if debug else " (run again with --debug for the traceback)"
        print(f"{prefix}: internal error: {type(err).__name__}: {what}{hint}", file=sys.stderr)
        return 1
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
        if stop is not None:
            stop()
        if args.quiet:
            if saved is None:
                os.environ.pop("TQDM_DISABLE", None)
            else:
                os.environ["TQDM_DISABLE"] = saved


def _command_actions(parser, args):
    """The argparse actions (options and arguments) of the command ``args`` ran."""
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return commands.choices[args.command]._actions


def _check_no_empty_values(parser, args):
    """Refuse an option or argument given as an empty (or blank) string before the command runs.

    Every command reads ``""`` as "not given" (``--params ""`` ran the default preset, ``--out ""`` wrote into
    the working folder, ``--effects ""`` ran every effect): a shell variable left unset must not silently
    change what runs.
    """
    from drakecreep.errors import InputError

    for action in _command_actions(parser, args):
        value = getattr(args, action.dest, None)
        values = value if isinstance(value, list) else [value]
        for v in values:
            if isinstance(v, str) and not v.strip():
                name = max(action.option_strings, key=len) if action.option_strings else action.metavar or action.dest
                raise InputError(name, v, "a non-empty value (leave the option out for its default)")


def _check_no_repeated_options(parser, args, argv):
    """Refuse an option that takes a value given more than once (``--feed 1 --feed 2`` ran at 2 mm/s without a
    word: argparse keeps the last). Options that collect (``--method``, ``-vv``) and flags may repeat."""
    from drakecreep.errors import InputError

    by_name = {name: action for action in _command_actions(parser, args)
               if isinstance(action, argparse._StoreAction) for name in action.option_strings}
    given = {}
    argv = [str(token) for token in argv]
    for i, token in enumerate(argv):
        if token == "--":  # what follows is positional
            break
        name, eq, value = token.partition("=")
        action = by_name.get(name)
        if action is not None:
            given.setdefault(action, []).append(value if eq else (argv[i + 1] if i + 1 < len(argv) else ""))
    for action, values in given.items():
        if len(values) > 1:
            raise InputError(max(action.option_strings, key=len), " then ".join(values),
                             "the option once (the last value would win without a word)")


#: errors of a path given by the user (exit 2); other OSErrors (a full disk, I/O errors) exit 1
_PATH_ERRNOS = {errno.ENAMETOOLONG, errno.ELOOP, errno.ENOTDIR, errno.EISDIR, errno.ENOENT, errno.EACCES,
                errno.EROFS, errno.EEXIST}


def _one_line(obj, limit=400):
    """``str(obj)`` on one line of at most ``limit`` characters."""
    try:
        text = str(obj)
    except Exception:  # noqa: BLE001
        text = f"<{type(obj).__name__}>"
    text = " ".join(text.split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _debug_traceback(debug):
    if debug:
        traceback.print_exc(file=sys.stderr)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
