"""Plot the EMPS validation run beside its closed-loop replay by a saved Drake model (no fitting here).

Run: ``PYTHONPATH=. python analysis/emps_drake_plot.py MODEL.yaml OUT.png`` with a model written by
``DrakeDiagnosis.save_model`` (``analysis/emps_drake.py`` writes ``emps_augmented.yaml``).
"""

import argparse
import sys
from pathlib import Path

import matplotlib
import yaml

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.backend_bases import FigureCanvasBase  # noqa: E402

from drakecreep.errors import InputError  # noqa: E402
from drakecreep.gap.drake_diagnosis import load_model  # noqa: E402
from drakecreep.gap.drake_replay import DrakeReplay, drake_replay_errors  # noqa: E402
from drakecreep.gap.identify import idim_start  # noqa: E402
from drakecreep.gap.measured import load_emps  # noqa: E402


def main(model_path, out):
    params, flexible, delay = load_model(model_path)
    val = load_emps("validation").run()
    est = load_emps("estimation").run()
    nominal = dict(params)
    nominal.update(idim_start([est]).parameters)  # the plain IDIM rigid model, for comparison
    for k in ("coulomb_asym", "viscous_asym", "stribeck_extra", "friction_ripple_cos", "friction_ripple_sin",
              "position_ripple_cos", "position_ripple_sin", "time_ripple_cos", "time_ripple_sin", "friction_drift"):
        nominal[k] = 0.0
    aug = DrakeReplay(val, flexible=flexible, delay=delay).simulate(params)
    nom = DrakeReplay(val).simulate(nominal)
    ea, en = drake_replay_errors(aug), drake_replay_errors(nom)
    fig, axes = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    t = val.t
    axes[0].plot(t, 1e3 * val.x_motor, "k", lw=1, label="measured")
    axes[0].set_ylabel("position [mm]")
    axes[1].plot(t, val.force, "k", lw=0.6, label="measured")
    axes[1].plot(t, nom.force, "C0", lw=0.6, label=f"IDIM rigid (force err {en['force']:.2f} %)")
    axes[1].plot(t, aug.force, "C3", lw=0.6, label=f"augmented (force err {ea['force']:.2f} %)")
    axes[1].set_ylabel("drive force [N]")
    axes[1].legend(loc="upper right", fontsize=8)
    axes[2].plot(t, val.force - nom.force, "C0", lw=0.5, label="measured - IDIM rigid")
    axes[2].plot(t, val.force - aug.force, "C3", lw=0.5, label="measured - augmented")
    axes[2].set_ylabel("force residual [N]")
    axes[2].set_xlabel("time [s]")
    axes[2].legend(loc="upper right", fontsize=8)
    fig.suptitle("EMPS validation file (DATA_EMPS_PULSES.mat), closed-loop Drake replay; models fitted on DATA_EMPS.mat only")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"wrote {out}: augmented {ea}, IDIM rigid {en}")


def _check(model_path, out):
    """The line refusing a model :func:`load_model` cannot read or an ``out`` matplotlib cannot write, or None."""
    try:
        load_model(model_path)
    except InputError as e:
        return str(e)
    except (OSError, ValueError, yaml.YAMLError) as e:
        return (f"MODEL.yaml: got {model_path!r}; allowed: a YAML written by DrakeDiagnosis.save_model "
                f"({type(e).__name__})")
    out = Path(out)
    formats = FigureCanvasBase.get_supported_filetypes()
    if not out.parent.is_dir() or (out.suffix and out.suffix[1:].lower() not in formats):
        return (f"OUT.png: got {str(out)!r}; allowed: a file in an existing directory, of a format matplotlib writes "
                "(" + ", ".join(sorted(formats)) + ")")
    return None


def cli(argv=None):
    """Parse ``argv``, check the model and the output path, and run :func:`main`; the exit status."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("model_path", metavar="MODEL.yaml", help="a model written by DrakeDiagnosis.save_model")
    ap.add_argument("out", metavar="OUT.png", help="figure to write")
    a = ap.parse_args(argv)
    problem = _check(a.model_path, a.out)
    if problem:
        print(problem, file=sys.stderr)
        return 2
    main(a.model_path, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(cli())
