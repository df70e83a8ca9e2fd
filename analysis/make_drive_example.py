"""Write the shipped example of runs of the project's own controller (``controller: {kind: drakecreep}``).

``drakecreep/data/examples/drive_lead_error.csv`` (six out-and-back runs at 20-40 mm/s, 0.5 s each, SI units),
its metadata ``drive_lead_error.yaml`` and the params file it declares, ``drive_rig.yaml``. The runs are
**synthetic**: the test rig of ``quick_replay_params(preset("paper"))`` (Stribeck friction, the nut's friction
on the table) simulated through the project's diagram with a 2 um lead error at the 5 mm lead that
``drive_rig.yaml`` leaves out, 2 N of white noise on ``u``, each run starting at another place on the screw.
``drakecreep diagnose drakecreep/data/examples/drive_lead_error.csv --out rep`` should find it. Run from the
repository root:

    python analysis/make_drive_example.py
"""

import argparse

import yaml

from drakecreep.data import data_dir
from drakecreep.gap.drake_replay import quick_replay_params, simulated_runs
from drakecreep.gap.measured import MeasuredData, save_measured
from drakecreep.params import preset, save_params, with_value

#: the example's recipe (also read by tests/data/test_examples.py to regenerate it)
SPEEDS = (0.02, 0.03, 0.025, 0.04, 0.035, 0.022)  # m/s
ORIGINS = (0.0, 0.0013, 0.0027, 0.0041, 0.0006, 0.0034)  # m
LEAD_ERROR = 2e-6  # m
NOISE, SEED, SAMPLES = 2.0, 11, 500  # N, -, per run


def example_runs():
    """The example's runs (``MeasuredRun``), their metadata declaring the test rig without its lead error."""
    rig = quick_replay_params(preset("paper"))
    truth = with_value(rig, "disturbance.lead_error_amplitude", LEAD_ERROR)
    return rig, simulated_runs(truth, SPEEDS, declared=rig, n=SAMPLES, noise=NOISE, seed=SEED, origins=ORIGINS)


def main():
    rig, runs = example_runs()
    out = data_dir() / "examples"
    csv, meta_path = save_measured(MeasuredData(runs=tuple(runs), meta=runs[0].meta), out / "drive_lead_error.csv")
    save_params(rig, out / "drive_rig.yaml")
    meta = yaml.safe_load(meta_path.read_text())
    meta["params"] = "drive_rig.yaml"  # the params file the user simulates, beside this YAML
    # this kind's gains and periods are the params file's: the metadata name the kind and the log's sample time
    meta["controller"] = {"kind": "drakecreep", "sample_time": meta["controller"]["sample_time"]}
    meta["source"] = ("synthetic: analysis/make_drive_example.py, the test rig with a 2 um lead error that "
                      "drive_rig.yaml leaves out, 2 N of noise on u")
    meta_path.write_text("# metadata of drive_lead_error.csv (format: docs/measured_format.md); SI units\n"
                         + yaml.safe_dump(meta, sort_keys=False))
    print(f"wrote {csv} ({csv.stat().st_size / 1e3:.0f} kB), {meta_path.name} and drive_rig.yaml")


if __name__ == "__main__":
    argparse.ArgumentParser(description=__doc__,
                            formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
