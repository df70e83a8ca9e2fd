"""EMPS reference results: the IDIM-LS table and the closed-loop replay errors beside the published values.

Everything is fitted on the estimation set (``DATA_EMPS.mat``). The validation set
(``DATA_EMPS_PULSES.mat``) is only scored with the parameters fixed beforehand.
"""

from __future__ import annotations

from drakecreep.gap.idim import (
    PARAMETER_NAMES,
    PARAMETER_UNITS,
    PUBLISHED_CROSS_TEST_ERROR_PERCENT,
    PUBLISHED_FIT_ERROR_PERCENT,
    PUBLISHED_IDIM,
    fit_idim,
    score_idim,
)
from drakecreep.errors import renaming
from drakecreep.gap.measured import emps_data_dir, load_emps
from drakecreep.gap.replay import PUBLISHED_REPLAY_ERRORS, SIGNALS, replay, replay_errors

__all__ = ["REPLAY_VARIANTS", "reference_results", "to_markdown"]

#: Replay variants: name -> (delay [samples], derivatives, description).
REPLAY_VARIANTS = {
    "documented": (0, "filtered", "documented loop, no delay; both positions through the IDIM filter"),
    "documented_model": (0, "model", "documented loop, no delay; simulator's own velocity/acceleration"),
    "delay1_model": (1, "model", "one-sample delay; simulator's own velocity/acceleration"),
}


def reference_results(data_dir=None):
    """Compute the EMPS reference tables.

    Parameters
    ----------
    data_dir : str or pathlib.Path, optional
        Folder of the ``.mat`` files (default :func:`drakecreep.gap.measured.emps_data_dir`).

    Returns
    -------
    dict
        ``idim`` (fit on the estimation set, with the published values), ``cross_test`` (scores on the
        validation set with the fixed parameters) and ``replay`` (errors per set and variant).
    """
    from pathlib import Path

    folder = Path(data_dir) if data_dir is not None else emps_data_dir()
    estimation = load_emps(folder / "DATA_EMPS.mat").run()
    validation = load_emps(folder / "DATA_EMPS_PULSES.mat").run()
    # the only fit; its refusals name the file ('samples: got 10' and 'run: got 'DATA_EMPS'' named none)
    fit = renaming(lambda field: f"{folder / 'DATA_EMPS.mat'}: {field}", fit_idim, estimation)
    idim = {
        "params": fit.params,
        "std": dict(zip(PARAMETER_NAMES, map(float, fit.std))),
        "published": dict(PUBLISHED_IDIM),
        "diff_percent": {k: 100.0 * (fit.params[k] / PUBLISHED_IDIM[k] - 1.0) for k in PARAMETER_NAMES},
        "fit_error_percent": fit.fit_error_percent,
        "published_fit_error_percent": PUBLISHED_FIT_ERROR_PERCENT,
        "n_samples": fit.n_samples,
        "other_border_reading": fit_idim(estimation, border_stage="decimated").params,
    }
    cross = {  # scoring only: the parameters above, fixed
        "readme_pipeline": score_idim(fit, validation),
        "force_filtered_too": score_idim(fit, validation, filter_force=True),
        "published": PUBLISHED_CROSS_TEST_ERROR_PERCENT,
    }
    rep = {}
    for name, run in (("estimation", estimation), ("validation", validation)):
        rep[name] = {"published": dict(PUBLISHED_REPLAY_ERRORS[name])}
        for variant, (delay, derivatives, _) in REPLAY_VARIANTS.items():
            rep[name][variant] = replay_errors(replay(run, fit, delay=delay), derivatives=derivatives)
    return {"data_dir": str(folder), "idim": idim, "cross_test": cross, "replay": rep}


def to_markdown(results):
    """The tables of :func:`reference_results` as Markdown text."""
    idim, cross, rep = results["idim"], results["cross_test"], results["replay"]
    lines = ["# EMPS reference results", "",
             f"Data: `{results['data_dir']}`. Fitted on DATA_EMPS.mat only; DATA_EMPS_PULSES.mat is scored "
             "with the fixed parameters.", "",
             "## IDIM-LS (estimation set)", "",
             "| parameter | published | drakecreep | std | difference |",
             "| --- | --- | --- | --- | --- |"]
    for k, unit in zip(PARAMETER_NAMES, PARAMETER_UNITS):
        lines.append(f"| {k} [{unit}] | {idim['published'][k]:.4f} | {idim['params'][k]:.4f} | "
                     f"{idim['std'][k]:.4f} | {idim['diff_percent'][k]:+.2f} % |")
    lines += [f"| relative force error of the fit | {idim['published_fit_error_percent']:.2f} % | "
              f"{idim['fit_error_percent']:.2f} % | | |",
              f"| cross-test on the validation set (score) | {cross['published']:.2f} % | "
              f"{cross['readme_pipeline']:.2f} % | | |", "",
              f"{idim['n_samples']} samples. Border samples dropped at the 1 ms rate before decimation; dropping "
              "them after decimation instead gives "
              + ", ".join(f"{k} = {v:.4f}" for k, v in idim["other_border_reading"].items()) + ".",
              f"Cross-test with the force also through the 100 Hz filter (not the README pipeline): "
              f"{cross['force_filtered_too']:.2f} %.", "",
              "## Closed-loop replay errors, 100 ||y - y_sim|| / ||y|| [%]", "",
              "| data set | model / variant | position | velocity | acceleration | force |",
              "| --- | --- | --- | --- | --- | --- |"]
    for name in ("estimation", "validation"):
        rows = [("published", rep[name]["published"])]
        rows += [(REPLAY_VARIANTS[v][2], rep[name][v]) for v in REPLAY_VARIANTS]
        for label, err in rows:
            lines.append(f"| {name} | {label} | " + " | ".join(f"{err[s]:.4g}" for s in SIGNALS) + " |")
    lines += ["", "Measured velocity and acceleration: Butterworth 100 Hz forward-backward and central differences "
              "of qm (no decimation). Measured force: gtau*vir (validation: including the 5 V pulses, which the "
              "replay applies as f_ext).", ""]
    return "\n".join(lines)
