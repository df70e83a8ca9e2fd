"""Write the shipped example of a measured run: ``drakecreep/data/examples/measured_mm_ms.csv`` + ``.yaml``.

Four out-and-back runs (20, 30, 60, 80 mm/s over 3 s each, 1 ms sampling) of a rigid axis with an
asymmetric Coulomb friction (+-50 N on top of a symmetric 20 N, viscous 200 N s/m, 90 kg), driven by the
EMPS position/velocity cascade and recorded as a user would export them: time in ms, positions in mm
(5 decimals = 10 nm, below the 50 nm encoder count), controller output in V (4 decimals). The data are
synthetic (drakecreep.gap.effects.synthesize_run, seed 2): the answer ``diagnose`` should find is
``asymmetric_friction``.

Run: ``python analysis/make_measured_example.py`` (a few seconds).
"""

from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from drakecreep.gap.benchmark import out_and_back
from drakecreep.gap.effects import EffectContext, get_effect, synthesize_run
from drakecreep.gap.measured import EMPS_CONTROLLER, MeasuredMeta, SensorMeta
from drakecreep.gap.replay import RigidModel

OUT = Path(__file__).resolve().parents[1] / "drakecreep" / "data" / "examples"
META = MeasuredMeta(u_units="V", u_gain=35.15, controller=EMPS_CONTROLLER,
                    sensors=SensorMeta(encoder_resolution=5e-8),
                    source="synthetic example (analysis/make_measured_example.py): rigid axis, 90 kg, "
                           "asymmetric Coulomb friction, EMPS cascade")


def main():
    t = np.arange(3000) * 1e-3
    model = RigidModel(M=90.0, Fv=200.0, Fc=20.0, offset=0.0)
    term = get_effect("asymmetric_friction").replay_term([-50.0], None, EffectContext(), {})
    rng = np.random.default_rng(2)
    frames = []
    for i, v in enumerate((0.02, 0.03, 0.06, 0.08)):
        run = synthesize_run(t, out_and_back(v, 0.01), META, model, [term],
                             force_noise=rng.normal(0, 0.5, t.size), label=f"r{i}")
        frames.append(pd.DataFrame({"t[ms]": np.round(run.t * 1e3, 6), "x_ref[mm]": np.round(run.x_ref * 1e3, 5),
                                    "x_motor[mm]": np.round(run.x_motor * 1e3, 5), "u[V]": np.round(run.u, 4),
                                    "run": run.label}))
    OUT.mkdir(parents=True, exist_ok=True)
    csv_path = OUT / "measured_mm_ms.csv"
    with open(csv_path, "w") as fh:
        fh.write("# synthetic measured runs, see measured_mm_ms.yaml and docs/measured_format.md\n")
        pd.concat(frames).to_csv(fh, index=False, lineterminator="\n")
    meta = {"u_units": "V", "u_gain": META.u_gain, "controller": META.controller.to_dict(),
            "sensors": {"encoder_resolution": 5.0e-8, "scale_resolution": 0.0}, "source": META.source,
            "notes": "time in ms and positions in mm in the CSV header; drakecreep converts them to SI."}
    (OUT / "measured_mm_ms.yaml").write_text(yaml.safe_dump(meta, sort_keys=False))
    print(f"wrote {csv_path} ({csv_path.stat().st_size / 1e3:.0f} kB)")


if __name__ == "__main__":
    main()
