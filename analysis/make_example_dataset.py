"""Write the shipped example of the measured-run format: a segment of the EMPS estimation file in shop units.

``drakecreep/data/examples/emps_segment.csv`` (time in ms, positions in mm, the controller output in V, the
external force in N; units in the header) and its metadata ``emps_segment.yaml``. The segment comes from
``DATA_EMPS.mat`` (the estimation file: the validation file stays held out). Run from the repository root:

    python analysis/make_example_dataset.py
"""

import argparse

import numpy as np
import yaml

from drakecreep.data import data_dir
from drakecreep.gap.measured import load_emps

SECONDS = 8.0


def main():
    data = load_emps("estimation")
    run = data.runs[0]
    n = int(np.searchsorted(run.t, SECONDS))
    out = data_dir() / "examples"
    out.mkdir(exist_ok=True)
    f_ext = run.f_ext[:n] if run.f_ext is not None else np.zeros(n)
    table = np.column_stack([run.t[:n] * 1e3, run.x_ref[:n] * 1e3, run.x_motor[:n] * 1e3, run.u[:n], f_ext])
    header = "t[ms],x_ref[mm],x_motor[mm],u[V],f_ext[N]"
    comment = ("# EMPS benchmark (Janot, Gautier, Brunot 2019), DATA_EMPS.mat, first 8 s, in shop units;\n"
               "# written by analysis/make_example_dataset.py. Format: docs/measured_format.md\n")
    path = out / "emps_segment.csv"
    with open(path, "w") as fh:
        fh.write(comment + header + "\n")
        np.savetxt(fh, table, delimiter=",", fmt=["%.3f", "%.7f", "%.7f", "%.6g", "%.6g"])
    c = data.meta.controller
    meta = dict(
        u_units="V", u_gain=float(data.meta.u_gain),
        controller=dict(kind="p_p_cascade", kp=c.kp, kv=c.kv, saturation=c.saturation, sample_time=c.sample_time),
        sensors=dict(encoder_resolution=data.meta.sensors.encoder_resolution, scale_resolution=0.0),
        source="EMPS benchmark (Janot, Gautier, Brunot 2019): DATA_EMPS.mat, first 8 s",
    )
    (out / "emps_segment.yaml").write_text(
        "# metadata of emps_segment.csv (format: docs/measured_format.md); SI units\n" + yaml.safe_dump(meta, sort_keys=False))
    print(f"wrote {path} ({path.stat().st_size / 1e3:.0f} kB, {n} rows) and its metadata")


if __name__ == "__main__":
    argparse.ArgumentParser(description=__doc__,
                            formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
