import base64
import json

import numpy as np

from drakecreep.gap.diagnosis import DiagnosisConfig, diagnose
from drakecreep.report.gap_report import to_json_dict, write_report
from drakecreep.gap.effects import EffectContext, get_effect, synthesize_run
from drakecreep.gap.benchmark import out_and_back
from drakecreep.gap.measured import EMPS_CONTROLLER, MeasuredMeta, SensorMeta
from drakecreep.gap.replay import RigidModel

META = MeasuredMeta(u_units="V", u_gain=35.15, controller=EMPS_CONTROLLER, sensors=SensorMeta(encoder_resolution=5e-8))
T = np.arange(3000) * 1e-3


def _result():
    model = RigidModel(M=90.0, Fv=200.0, Fc=20.0, offset=0.0)
    term = get_effect("asymmetric_friction").replay_term([50.0], None, EffectContext(), {})
    rng = np.random.default_rng(0)
    runs = [synthesize_run(T, out_and_back(v, 0.01), META, model, [term], force_noise=rng.normal(0, 0.5, T.size),
                           label=f"r{i}") for i, v in enumerate((0.02, 0.03, 0.06, 0.08))]
    return diagnose(runs[0::2], runs[1::2], DiagnosisConfig(effects=("asymmetric_friction", "stribeck")))


def test_report_has_embedded_plots_and_the_json_keys(tmp_path):
    res = _result()
    html_path, json_path = write_report(res, tmp_path / "out")
    text = html_path.read_text()
    imgs = text.split("data:image/png;base64,")[1:]
    assert len(imgs) >= 5
    png = base64.b64decode(imgs[0].split("'")[0])
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert "asymmetric_friction" in text
    data = json.loads(json_path.read_text())
    assert {"where", "ranking", "unexplained_share", "claimed", "shrink"} <= set(data)
    assert "constant_speed" in data["where"]["regimes"]["speed"]
    assert "screw" in data["where"]["orders"]["force"]
    row = data["ranking"][0]
    assert {"effect", "score", "params", "idim_rms_N", "replay_rms"} <= set(row)
    assert row["replay_rms"]["after"]["force_N"] < row["replay_rms"]["before"]["force_N"]


def test_json_form_drops_internal_objects_and_arrays():
    res = _result()
    data = to_json_dict(res)
    json.dumps(data)  # serializable
    assert "_fits" not in data and "_gap_before" not in data
    assert "spectra" not in data["where"]
