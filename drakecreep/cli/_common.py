"""Options and conversions shared by the subcommands (report units at the edge: mm/s, N/um)."""

import argparse
import dataclasses
import json
import math

from drakecreep.errors import InputError
from drakecreep.files import to_jsonable
from drakecreep.params import PRESETS, load_params, preset, with_value

__all__ = ["add_params_options", "params_from_args", "positive_float", "print_json", "feed_from_mm_s", "number", "workers",
           "count", "integer_in", "MAX_WORKERS", "POSITIVE_FEED", "check_feed", "comma_items", "distinct", "names"]


def number(text):
    """argparse type: a finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"got {text!r}; allowed: a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"got {text!r}; allowed: a finite number")
    return value


def comma_items(text, option, allowed):
    """The stripped comma-separated items of an option's value; an empty item (``1,,2``, ``1,``) is an error
    (an item lost, not a shorter list)."""
    items = [x.strip() for x in text.split(",")]
    if not all(items):
        raise InputError(option, text, allowed + " (no empty item)")
    return items


def distinct(values, option, text, allowed):
    """``values`` if no value repeats, else an error naming ``option`` (its value ``text``) with ``allowed``."""
    if len(set(values)) != len(values):
        raise InputError(option, text, allowed)
    return values


def names(text, option=None):
    """A comma-separated list of names as a tuple.

    Without ``option`` blank items are skipped. With it (the option the list came from) a blank item or a name
    given twice is an :class:`~drakecreep.errors.InputError` naming the option: ``--effects ,`` ran no candidate
    at all, and ``--effects lead_error,lead_error`` fitted one twice.
    """
    items = [x.strip() for x in text.split(",")]
    if option is None:
        return tuple(x for x in items if x)
    if not all(items):
        raise InputError(option, text, "comma-separated names, none blank")
    twice = sorted({x for x in items if items.count(x) > 1})
    if twice:
        raise InputError(option, text, f"each name once ({', '.join(twice)} given twice)")
    return tuple(items)


def positive_float(text):
    """argparse type: a finite number > 0."""
    value = number(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"got {text!r}; allowed: a finite number > 0")
    return value


def add_params_options(parser, friction=True):
    """``--params FILE`` / ``--preset NAME`` (and ``--friction LAW``)."""
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--params", metavar="FILE", help="parameter file (YAML, SI units)")
    group.add_argument("--preset", default="paper", choices=PRESETS, help="built-in parameter set (default: paper)")
    if friction:
        parser.add_argument(
            "--friction", choices=("coulomb", "stribeck", "lugre", "gms"), help="friction law (default: from the parameters)"
        )


def existing_path(option, path):
    """``path`` unless it does not exist: then an :class:`~drakecreep.errors.InputError` naming ``option`` (the
    generic 'No such file or directory' line did not say which option the path came from)."""
    if path is not None and not path_exists(option, path):
        raise InputError(option, str(path), "an existing file (no such file or directory)")
    return regular_file(option, path)


def regular_file(option, path):
    """``path`` (``None`` passes) unless it names a folder or a device: then an :class:`~drakecreep.errors.InputError`
    naming ``option`` (the file readers said 'adir: got 'adir (a directory)'', no option)."""
    from pathlib import Path

    if path is not None and Path(path).exists() and not Path(path).is_file():
        raise InputError(option, str(path), "a regular file (this is " + ("a folder)" if Path(path).is_dir()
                                                                          else "a device or other special file)"))
    return path


def path_exists(option, path):
    """``Path(path).exists()``; a name the system refuses (longer than it allows) is an
    :class:`~drakecreep.errors.InputError` naming ``option`` (it was 'File name too long: /tmp/aaa...', no option)."""
    from pathlib import Path

    try:
        return Path(path).exists()
    except OSError as err:
        raise InputError(option, str(path), f"a path the system accepts ({err.strerror})") from None


def params_from_args(args):
    """:class:`~drakecreep.params.DriveParams` from ``--params``/``--preset`` and overrides."""
    params = load_params(existing_path("--params", args.params)) if args.params else preset(args.preset)
    if getattr(args, "friction", None):
        params = with_value(params, "friction.law", args.friction)
    return params


def print_json(obj):
    """One JSON object on stdout."""
    print(json.dumps(to_jsonable(obj)))


#: most worker processes of one command (``--workers 99999`` started a process per queued case)
MAX_WORKERS = 256


def _integer_at_least(text, minimum, maximum=None):
    """An integer in ``[minimum, maximum]``; else an argparse type error in the refusals' own form (``--n-null -1``
    said '... must be >= 0' where ``--n-null 1001`` said '--n-null: got 1001; allowed: an integer in [0, 1000]')."""
    allowed = f"an integer >= {minimum}" if maximum is None else f"an integer in [{minimum}, {maximum}]"
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"got {text!r}; allowed: {allowed}") from None
    if value < minimum or (maximum is not None and value > maximum):
        raise argparse.ArgumentTypeError(f"got {text!r}; allowed: {allowed}")
    return value


def workers(text):
    """argparse type: a number of worker processes, an integer in [1, :data:`MAX_WORKERS`]."""
    return _integer_at_least(text, 1, MAX_WORKERS)


def count(text):
    """argparse type: a count, an integer >= 0."""
    return _integer_at_least(text, 0)


def integer_in(text, minimum, maximum):
    """argparse type (in a wrapper that gives the bounds): an integer in ``[minimum, maximum]``."""
    return _integer_at_least(text, minimum, maximum)


#: what a feed option of the linear analyses takes (margins, tune, report, critical): one way, in the range of every
#: command's feeds (critical said 'a finite speed > 0 in mm/s', the others 'a feed > 0 mm/s')
POSITIVE_FEED = "a feed in [1e-4, 1000] mm/s (> 0: the analysis takes a feed in +x)"


def check_feed(params, scenario, option, mm_s):
    """Raise :class:`InputError` naming ``option`` (a feed of ``mm_s`` mm/s) when the drive cannot slide steadily at
    ``scenario``'s feed: the force it takes is beyond the drive's limit (the operating point said 'feed: got 0.001',
    the scenario's field in m/s, and blamed the feed for what is mostly the params' load and friction)."""
    import numpy as np  # (not at start-up: every command's --help imports this module)

    from drakecreep.model.steady import drive_limit, nut_on_table, sliding_overload, steady_sliding

    overload = sliding_overload(params, scenario)
    if overload is not None:
        force, limit = overload
        feeds = np.geomspace(1e-7, 1.0, 43)  # the commands' feeds, 1e-4 to 1000 mm/s
        needs = [sliding_overload(params, dataclasses.replace(scenario, feed=float(v))) for v in feeds]
        if all(n is not None for n in needs):
            # no feed slides: the load and the friction are the drive's, not the feed's ('--feed: got 1.0', an option
            # not given, 'allowed: a feed the drive can slide at', where none can)
            raise InputError("--load-case", scenario.load_case, f"a load case the drive can hold at some feed: this one "
                             f"takes at least {min(n[0] for n in needs):.4g} N at 1e-4 to 1000 mm/s, beyond the "
                             f"drive's limit {limit:.4g} N ({drive_limit(params)[1]} against the params file's load "
                             "and friction)")
        _, friction, spring, _, _ = steady_sliding(nut_on_table(params), scenario)
        raise InputError(option, mm_s, f"a feed in mm/s the drive can slide at: at load case {scenario.load_case} it "
                         f"takes {force:.4g} N (load {spring - friction:.4g} N, friction {friction:.4g} N, motor drag "
                         f"{force - spring:.4g} N), beyond the drive's limit {limit:.4g} N ({drive_limit(params)[1]})")


def feed_from_mm_s(value, option="--feed"):
    """m/s from a CLI value in mm/s, or an InputError naming the option."""
    from drakecreep.scenario import MAX_FEED

    # below 1e-4 mm/s (0.1 um/s) a run of seconds moves a few scale counts: nothing left to measure, and
    # the analyses' 1/v terms overflow (1e-300 mm/s ran forever)
    if not math.isfinite(value) or not 1e-4 <= abs(value) <= MAX_FEED * 1e3:
        raise InputError(option, value, f"a feed of magnitude in [1e-4, {MAX_FEED * 1e3:g}] mm/s")
    return value * 1e-3


def check_duration(value, option="--duration"):
    """``value`` (s, already > 0) unless it is beyond one run's longest, :data:`drakecreep.scenario.MAX_DURATION`:
    an InputError naming the option (the scenario's message named its field, 'duration: got 1e9')."""
    from drakecreep.scenario import MAX_DURATION

    if not value <= MAX_DURATION:
        raise InputError(option, value, f"a time in (0, {MAX_DURATION:g}] s")
    return value
