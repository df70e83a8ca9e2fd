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
