import numpy as np

from drakecreep.report import loop_plots
from drakecreep.servo.polemap import PoleMap


def test_pole_map_png(tmp_path):
    K = np.array([2e6, 4e6, 8e6])
    Y = np.tile(np.array([[-100.0], [0.0], [100.0]]), (1, 3))
    pm = PoleMap(feed=1e-4, mass=40.0, friction_drop=8.0, stiffness=K, damping=Y, closed_loop=-Y / 50 + 0.5,
                 mechanism=-Y / 50, nominal=(4e6, 10.0), sim_stiffness=np.array([2e6, 8e6]),
                 sim_damping=np.array([-50.0, 50.0]), sim_creep=np.array([True, False]))
    path = loop_plots.plot_pole_map(pm, tmp_path / "map.png")
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
