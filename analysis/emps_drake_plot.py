"""Plot the EMPS validation run beside its closed-loop replay by a saved Drake model (no fitting here).

Run: ``PYTHONPATH=. python analysis/emps_drake_plot.py MODEL.yaml OUT.png`` with a model written by
``DrakeDiagnosis.save_model`` (``analysis/emps_drake.py`` writes ``emps_augmented.yaml``).
"""

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

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


if __name__ == "__main__":
    main(*sys.argv[1:3])
