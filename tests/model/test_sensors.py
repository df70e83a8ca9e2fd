import math

import numpy as np
import pytest

from drakecreep.model.sensors import LinearScale, MotorEncoder, encoder_resolution, quantize


def test_quantize_counts_down():
    assert quantize(1.049, 0.1) == pytest.approx(1.0)
    assert quantize(-0.01, 0.1) == pytest.approx(-0.1)
    assert quantize(0.123456, 0.0) == 0.123456


def test_encoder_reading_and_resolution():
    enc = MotorEncoder(4096)
    assert encoder_resolution(4096) == pytest.approx(2 * math.pi / 4096)
    c = enc.CreateDefaultContext()
    theta = 1000.3 * 2 * math.pi / 4096
    enc.get_input_port(0).FixValue(c, [theta, 7.0])
    np.testing.assert_allclose(enc.get_output_port(0).Eval(c), [1000 * 2 * math.pi / 4096, 7.0])
    assert enc.ToAutoDiffXd().counts_per_rev == 4096


def test_scale_reading_and_ideal_scale():
    scale = LinearScale(50e-9)
    c = scale.CreateDefaultContext()
    scale.get_input_port(0).FixValue(c, [1.23456789e-3, 0.0])
    assert scale.get_output_port(0).Eval(c)[0] == pytest.approx(1.23455e-3)
    ideal = LinearScale(0.0)
    c = ideal.CreateDefaultContext()
    ideal.get_input_port(0).FixValue(c, [1.23456789e-3, 0.0])
    assert ideal.get_output_port(0).Eval(c)[0] == 1.23456789e-3
    assert scale.ToSymbolic().resolution == 50e-9


def test_scale_interpolation_error_is_periodic_in_position():
    from drakecreep.model.sensors import scale_reading

    scale = LinearScale(0.0, 0.2e-6, 20e-6)
    c = scale.CreateDefaultContext()
    for x in (5e-6, 1.2345e-3):
        scale.get_input_port(0).FixValue(c, [x, 0.0])
        expected = x + 0.2e-6 * math.sin(2 * math.pi * x / 20e-6)
        assert scale.get_output_port(0).Eval(c)[0] == pytest.approx(expected, abs=1e-15)
        assert scale.read(x) == scale_reading(x, 0.0, 0.2e-6, 20e-6)
    xs = np.linspace(0, 1e-4, 11)
    np.testing.assert_allclose(scale.read(xs), xs + 0.2e-6 * np.sin(2 * math.pi * xs / 20e-6))
    sym = scale.ToSymbolic()
    assert (sym.interpolation_error, sym.signal_period) == (0.2e-6, 20e-6)


def test_differenced_speed_quantum_and_period_check():
    from drakecreep.errors import InputError
    from drakecreep.model.sensors import differenced_speed, scale_reading

    t = np.arange(0.0, 0.1 + 1e-9, 2.5e-4)
    x = 1.03e-3 * t  # 1.03 mm/s: 10.3 counts of 100 nm per millisecond
    ts, v = differenced_speed(t, scale_reading(x, 100e-9), 1e-3)
    assert ts[0] == pytest.approx(1e-3) and len(v) == 100
    assert set(np.round(v / 1e-4).astype(int)) == {10, 11}
    assert v.mean() == pytest.approx(1.03e-3, rel=0.01)
    with pytest.raises(InputError):
        differenced_speed(t, x, 3e-4)


def test_diagram_scale_takes_the_sensor_parameters():
    from drakecreep.model.diagram import build_diagram
    from drakecreep.params import preset, with_value
    from drakecreep.scenario import Scenario

    p = with_value(preset("paper"), "sensors.scale_interpolation_error", 0.1e-6)
    p = with_value(p, "sensors.scale_signal_period", 40e-6)
    scale = build_diagram(p, Scenario()).systems["scale"]
    assert (scale.interpolation_error, scale.signal_period) == (0.1e-6, 40e-6)
    assert build_diagram(p, Scenario(), ideal_sensors=True).systems["scale"].interpolation_error == 0.0
