"""``drakecreep modal FILE.csv``: identify one joint mode (fn, damping, k, c) from a hammer test.

The CSV holds either an FRF (columns ``f_Hz,re,im``; choose its kind with ``--frf-type``) or time
records (columns ``t,force,response``; the response kind with ``--response``), separated by ``,``, ``;`` or a
tab. Lines starting with ``#`` are ignored. Results by the half-power bandwidth method (the paper's) and by a
least-squares SDOF fit of the complex FRF.
"""

import json
import math

import numpy as np

from drakecreep.cli._common import existing_path
from drakecreep.errors import InputError
from drakecreep.files import to_jsonable

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    """Register ``modal``."""
    p = subparsers.add_parser("modal", help="half-power / SDOF-fit identification of a hammer test",
                              description=__doc__.split("\n\n")[0])
    p.add_argument("file", metavar="FILE.csv", help="f_Hz,re,im  or  t,force,response")
    p.add_argument("--mass", type=float, metavar="KG",
                   help="modal mass for k = m wn^2, c = 2 zeta m wn (half-power)")
    p.add_argument("--frf-type", choices=("receptance", "mobility", "accelerance"),
                   help="kind of FRF in an f_Hz,re,im file (default receptance)")
    p.add_argument("--response", choices=("displacement", "velocity", "acceleration"),
                   help="kind of response in a t,force,response file (default acceleration)")
    p.add_argument("--pulse-width", type=float, metavar="S",
                   help="impulse duration for the force window (default: estimated from the force)")
    p.add_argument("--exp-tau", type=float, metavar="S",
                   help="apply an exponential window of this time constant (corrected for)")
    p.add_argument("--fmin", type=float, metavar="HZ", help="lower end of the band holding the mode")
    p.add_argument("--fmax", type=float, metavar="HZ", help="upper end of the band holding the mode")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=run)
    return p


def _uniform_step(x, name):
    d = np.diff(x)
    if not (np.all(d > 0) and np.allclose(d, d[0], rtol=1e-6, atol=0.0)):
        raise InputError(name, "non-uniform or non-increasing", "uniformly spaced increasing values")
    return float(d[0])


def _estimate_pulse_width(force, dt):
    """Width of the impulse: time the force stays above 10 % of its peak (at least 2 samples)."""
    above = np.abs(force) >= 0.1 * np.max(np.abs(force))
    idx = np.flatnonzero(above)
    return max((idx[-1] - idx[0] + 1) * dt, 2 * dt)


def _check_windows(args, force, dt, estimated):
    """--pulse-width and --exp-tau against the record: a window that cuts the impulse, or keeps the whole record,
    changed the result or nothing without a word (found by fuzzing: a width of 1e-9 s gave k = 1.8e5 N/m against
    1.14e6, a width of 10 s on a 1 s record the result without it)."""
    record = dt * force.size
    width = args.pulse_width
    if width is not None and width < 0.5 * estimated:
        raise InputError("--pulse-width", width, f">= {0.5 * estimated:.3g} s, half the recorded impulse (the force "
                         f"stays above 10 % of its peak for {estimated:.3g} s; a shorter window cuts it)")
    if width is not None and 3.0 * width > record:
        raise InputError("--pulse-width", width, f"<= {record / 3.0:.3g} s, a third of the record ({record:.3g} s: the "
                         "force window keeps three widths around the peak, so a longer one keeps the whole record)")
    peak = dt * int(np.argmax(np.abs(force)))
    if args.exp_tau is not None and peak > args.exp_tau * math.log(100.0):
        raise InputError("--exp-tau", args.exp_tau, f">= {peak / math.log(100.0):.3g} s: the exponential window starts "
                         f"at the record's start and would keep less than 1 % of the impulse at {peak:.3g} s")


def _limits(header, data):
    """The lowest and the highest frequency a file covers [Hz]: its FRF's f_Hz, or 0 to a time record's Nyquist."""
    from drakecreep.paper.modal import FRF_COLUMNS

    if header == FRF_COLUMNS:
        return float(data[0, 0]), float(data[-1, 0])
    return 0.0, 0.5 / float(np.median(np.diff(data[:, 0])))


def _span(header, data):
    """The frequencies a file covers, as text (:func:`_limits`)."""
    lowest, highest = _limits(header, data)
    return f"{lowest:g}-{highest:g} Hz"


def _identify(args, header, data, band):
    """The identification of an FRF or a time record, and the kind of its FRF or response."""
    from drakecreep.paper.modal import FRF_COLUMNS, HammerTest, identify_frf, identify_hammer_test

    if header == FRF_COLUMNS:
        f = data[:, 0]
        _uniform_step(f, "f_Hz")
        kind = args.frf_type or "receptance"
        ident = identify_frf(f, data[:, 1] + 1j * data[:, 2], kind, args.mass, band, args.exp_tau)
    else:
        dt = _uniform_step(data[:, 0], "t")
        force = data[:, 1]
        if not np.any(force != 0.0):
            raise InputError("force", "all zero", "a recorded impulse")
        estimated = _estimate_pulse_width(force, dt)
        _check_windows(args, force, dt, estimated)
        width = args.pulse_width if args.pulse_width is not None else estimated
        kind = args.response or "acceleration"
        test = HammerTest(data[:, 0], force[None, :], data[:, 2][None, :], 1.0 / dt, kind)
        ident = identify_hammer_test(test, width, args.mass, args.exp_tau, band=band)
    return ident, kind


def run(args):
    """Read the file, identify, print."""
    from drakecreep.paper.modal import FRF_COLUMNS, read_hammer_csv

    # bounded as hertz --mass: 1e300 kg printed k = 4.852e+305 N/m, exit 0
    if args.mass is not None and not (math.isfinite(args.mass) and 1e-6 <= args.mass <= 1e5):
        raise InputError("--mass", args.mass, "a modal mass in [1e-06, 100000] kg")
    if args.exp_tau is not None and not (math.isfinite(args.exp_tau) and args.exp_tau > 0):
        raise InputError("--exp-tau", args.exp_tau, "> 0 s")
    if args.pulse_width is not None and not (math.isfinite(args.pulse_width) and args.pulse_width > 0):
        raise InputError("--pulse-width", args.pulse_width, "> 0 s")  # -1 was reported as a bad frequency band
    for option, value in (("--fmin", args.fmin), ("--fmax", args.fmax)):
        if value is not None and not (math.isfinite(value) and value >= 0.0):
            raise InputError(option, value, "a finite frequency >= 0 Hz")
    if args.fmin is not None and args.fmax is not None and not args.fmax > args.fmin:
        # the band search said 'frequency band: got (200.0, 100.0)'
        raise InputError("--fmax", args.fmax, f"a frequency above --fmin ({args.fmin:g} Hz)")
    header, data = read_hammer_csv(existing_path("FILE.csv", args.file))
    # an option of the other kind of file was ignored without a word (--response velocity on an FRF)
    for option, value, frf in (("--pulse-width", args.pulse_width, False), ("--response", args.response, False),
                               ("--frf-type", args.frf_type, True)):
        if value is not None and (header == FRF_COLUMNS) != frf:
            raise InputError(option, value, "only with an f_Hz,re,im file (this one is a time record)" if frf
                             else "only with a t,force,response file (this one is an FRF)")
    band = None
    if args.fmin is not None or args.fmax is not None:
        band = (args.fmin, args.fmax)
    try:
        ident, kind = _identify(args, header, data, band)
    except InputError as err:  # the option, not the library's parameter
        if err.field == "exp_tau":
            raise err.renamed("--exp-tau") from None
        if err.field in ("frequency band", "band") and band is not None:  # a band past the file's data
            # the end given alone, or above the file's data; else the upper end: below the data, or the end of a
            # band too narrow ('--fmin 0 --fmax 1e-9' blamed --fmin)
            highest = _limits(header, data)[1]
            if args.fmax is None or (args.fmin is not None and args.fmin >= highest):
                option, value = "--fmin", args.fmin
            else:
                option, value = "--fmax", args.fmax
            top = "f_Hz" if header == FRF_COLUMNS else "frequencies"
            raise InputError(option, value, f"{err.allowed} (the file's {top} run {_span(header, data)}; "
                             "--fmin and --fmax select within them)") from None
        raise
    fit = ident.fit
    out = {
        "input": {"file": str(args.file), "kind": kind, "modal_mass_kg": args.mass},
        "band_Hz": list(ident.band),
        "half_power": {"fn_Hz": ident.fn_half_power, "zeta": ident.zeta_half_power,
                       "f1_Hz": ident.half_power.f1, "f2_Hz": ident.half_power.f2,
                       "k_N_per_m": None if math.isnan(ident.k_half_power) else ident.k_half_power,
                       "c_Ns_per_m": None if math.isnan(ident.c_half_power) else ident.c_half_power},
        "sdof_fit": None if fit is None else {"fn_Hz": fit.fn, "zeta": fit.zeta, "k_N_per_m": fit.k,
                                              "m_kg": fit.m, "c_Ns_per_m": fit.c},
    }
    if fit is None:
        out["sdof_fit_failure"] = ident.fit_failure
    if args.json:
        print(json.dumps(to_jsonable(out), indent=2))  # a non-finite number as "inf", valid JSON
        return 0
    hp = out["half_power"]
    print(f"{args.file}: {kind}, band {ident.band[0]:.4g}-{ident.band[1]:.4g} Hz")
    line = f"half-power: fn = {hp['fn_Hz']:.5g} Hz, zeta = {hp['zeta']:.4g}"
    if hp["k_N_per_m"] is not None:
        line += (f", k = {hp['k_N_per_m']:.4g} N/m, c = {hp['c_Ns_per_m']:.4g} N s/m "
                 f"(modal mass {args.mass:.4g} kg)")
    else:
        line += " (give --mass for k and c)"
    print(line)
    if fit is None:
        print(f"SDOF fit: failed ({ident.fit_failure})")
    else:
        print(f"SDOF fit:   fn = {fit.fn:.5g} Hz, zeta = {fit.zeta:.4g}, k = {fit.k:.4g} N/m, "
              f"m = {fit.m:.4g} kg, c = {fit.c:.4g} N s/m")
    return 0
