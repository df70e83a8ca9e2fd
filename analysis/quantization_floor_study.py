"""How much of the ``drakecreep`` kind's force residual is the encoder's speed quantization (docs 3ce).

Under the PI cascade the speed loop differences the motor encoder's counts every 0.25 ms: one count of 100 nm is
a speed step of 0.4 mm/s, which the proportional gain (about 2.5e4 N s/m) turns into a force step of 10 N. The
recorded force (the controller's output) therefore carries a ripple whose pattern follows the fractional counts
per tick, a deterministic but hypersensitive function of the motor's position. The replay has the same encoder
(``replay_drakecreep(..., quantize=True)``, the product's default) and makes a ripple of the same size, but its
pattern is not the measured one; sample by sample the two add.

For each dataset (``SEED:EFFECT:AXIS`` of :func:`drakecreep.gap.benchmark.dataset_spec`; use development seeds)
this script regenerates it and replays each held-out and audit run with the dataset's declared params file
(no fit: the friction mismatch of the declared file stays in every number), with and without the encoder's
quantization, and where the truth's withheld effect has a true model
(:func:`drakecreep.gap.benchmark.true_drive_values`) also with it. It prints per run, as mean squares [N^2]:

* ``meas>100``: the measured force's energy above ``--cutoff`` (the zero-phase Butterworth low-pass of the IDIM
  processing, :func:`drakecreep.gap.idim.filtered_derivatives`) and, beside it, the unquantized replay's;
* ``res Q`` / ``res U``: the residual energy of the quantized / unquantized replay, whole and below the cutoff;
* ``effect``: the energy of the force the true effect adds in the quantized replay, whole and below the cutoff
  (where the two replays' ripple patterns differ, the whole one counts that difference too).

Nothing in the product is changed by it. Run:
``PYTHONPATH=. python analysis/quantization_floor_study.py 9013:null:flexible [...] [--cutoff 100] [--json OUT]``
"""

import argparse
import json
import sys

import numpy as np

from drakecreep.errors import InputError
from drakecreep.files import check_output_file, write_text

__all__ = ["run_energies", "main"]


def _ms(x):
    return float(np.mean(np.square(x)))


def run_energies(run, params, true=None, cutoff=100.0):
    """Mean squares [N^2] of one run's force residuals, quantized and not, whole and below ``cutoff``.

    Parameters
    ----------
    run : drakecreep.gap.measured.MeasuredRun
    params : drakecreep.params.DriveParams
        The params file replayed.
    true : dict, optional
        ``path -> value`` of the truth's effect; adds ``effect`` / ``effect_lp``.
    cutoff : float
        Low-pass cut-off [Hz].

    Returns
    -------
    dict
    """
    from drakecreep.gap.drake_replay import replay_drakecreep
    from drakecreep.gap.drive_fit import _with
    from drakecreep.gap.idim import filtered_derivatives

    def lp(x):
        return filtered_derivatives(np.asarray(x, dtype=float), run.dt, cutoff)[0]

    fm = np.asarray(run.force, dtype=float)
    fq = np.asarray(replay_drakecreep(run, params).force)
    fu = np.asarray(replay_drakecreep(run, params, quantize=False).force)
    v = np.abs(np.gradient(np.asarray(run.x_motor), run.dt))
    out = {"run": run.label, "vmax_mm_s": 1e3 * float(v.max()), "meas": _ms(fm - fm.mean()),
           "meas_hf": _ms(fm - lp(fm)), "replay_q_hf": _ms(fq - lp(fq)), "replay_u_hf": _ms(fu - lp(fu)),
           "res_q": _ms(fm - fq), "res_q_lp": _ms(lp(fm - fq)), "res_u": _ms(fm - fu), "res_u_lp": _ms(lp(fm - fu))}
    if true is not None:
        fe = np.asarray(replay_drakecreep(run, _with(params, true)).force)
        out.update(effect=_ms(fe - fq), effect_lp=_ms(lp(fe - fq)), res_true_q=_ms(fm - fe),
                   res_true_q_lp=_ms(lp(fm - fe)))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("datasets", nargs="+", help="SEED:EFFECT:AXIS (development seeds)")
    ap.add_argument("--cutoff", type=float, default=100.0, help="low-pass cut-off [Hz] (default 100, the IDIM's)")
    ap.add_argument("--json", help="write the rows here")
    a = ap.parse_args(argv)
    from drakecreep.gap import benchmark as B

    try:
        specs = [B.dataset_spec(s) for s in a.datasets]
    except InputError as e:
        print(f"quantization_floor_study: error: {e}", file=sys.stderr)
        return 2
    if not 0.0 < a.cutoff < 500.0:
        print(f"quantization_floor_study: error: --cutoff: got {a.cutoff:g}; allowed: in (0, 500) Hz", file=sys.stderr)
        return 2
    if a.json:
        try:
            check_output_file(a.json, "--json")
        except InputError as e:
            print(f"quantization_floor_study: error: {e}", file=sys.stderr)
            return 2
    rows = []
    for seed, withheld, axis in specs:
        ds = B.generate_dataset(seed, withheld=withheld, kind="drakecreep", axis=axis)
        true = B.true_drive_values(ds.truth) if withheld else None
        print(f"== {seed} {'/'.join(withheld) or 'null'} {axis} (SNR {ds.snr:.1f}) true model: {true is not None}")
        print("run    vmax mm/s | meas>cut  replayQ>cut replayU>cut | res Q  res Q<cut | res U  res U<cut"
              " | effect effect<cut   [N^2]")
        for r in list(ds.test) + list(ds.audit):
            e = run_energies(r, r.meta.params, true, a.cutoff)
            e.update(seed=seed, withheld=list(withheld), axis=axis)
            rows.append(e)
            eff = (f" | {e['effect']:6.2f} {e['effect_lp']:6.2f}" if "effect" in e else "")
            print(f"{e['run']:6s} {e['vmax_mm_s']:8.1f} | {e['meas_hf']:7.2f} {e['replay_q_hf']:9.2f} "
                  f"{e['replay_u_hf']:10.2f}  | {e['res_q']:6.2f} {e['res_q_lp']:8.2f} | {e['res_u']:6.2f} "
                  f"{e['res_u_lp']:8.2f}{eff}", flush=True)
    keys = ("meas_hf", "res_q", "res_q_lp", "res_u", "res_u_lp")
    med = {k: float(np.median([r[k] for r in rows])) for k in keys}
    print("medians [N^2]: " + ", ".join(f"{k} {v:.2f}" for k, v in med.items()))
    share = np.median([1.0 - r["res_q_lp"] / r["res_q"] for r in rows])
    print(f"median share of the quantized replay's residual above {a.cutoff:g} Hz: {100 * share:.0f} %")
    eff = [r for r in rows if "effect" in r]
    if eff:
        gain = np.median([(r["effect_lp"] / r["res_true_q_lp"]) / (r["effect"] / r["res_true_q"]) for r in eff])
        print(f"median gain of effect / residual-with-the-true-effect below {a.cutoff:g} Hz over the whole band: "
              f"{gain:.2f} ({len(eff)} runs)")
    if a.json:
        write_text(a.json, json.dumps({"cutoff_Hz": a.cutoff, "rows": rows, "medians": med}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
