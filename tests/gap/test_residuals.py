import numpy as np
import pytest

from drakecreep.errors import InputError
from drakecreep.gap.benchmark import out_and_back
from drakecreep.gap.residuals import (
    REGIMES,
    classify_regimes,
    dominant_oscillation,
    operating_map,
    oscillates_at,
    oscillation_band_errors,
    oscillation_log_errors,
    order_spectrum,
    regime_shares,
    sustained_oscillation,
    time_spectrum,
    whiteness,
)

T = np.arange(3000) * 1e-3
X_REF = out_and_back(0.05, 0.0)
V = np.gradient(X_REF, 1e-3)


def test_regimes_of_an_out_and_back_move():
    labels = classify_regimes(T, X_REF, V)
    assert labels[100] == "dwell"  # before the first leg
    assert labels[int(0.2 / 1e-3) + 650] == "constant_speed"  # middle of the out leg
    assert labels[int(0.2 / 1e-3) + 100] == "acceleration"
    assert set(labels) <= set(REGIMES)


def test_stick_when_the_reference_moves_but_the_axis_does_not():
    v = V.copy()
    v[800:900] = 0.0
    labels = classify_regimes(T, X_REF, v)
    assert np.all(labels[830:870] == "stick") or np.all(np.isin(labels[830:870], ["stick", "reversal"]))
    assert "stick" in set(labels[800:900])


def test_regime_shares_sum_to_one_and_find_the_regime():
    labels = classify_regimes(T, X_REF, V)
    r = np.where(labels == "constant_speed", 1.0, 0.01)
    shares = regime_shares(r, labels)
    assert sum(s["energy_share"] for s in shares.values()) == pytest.approx(1.0)
    assert sum(s["time_share"] for s in shares.values()) == pytest.approx(1.0)
    assert max(shares, key=lambda k: shares[k]["energy_share"]) == "constant_speed"


def test_order_spectrum_finds_a_periodic_residual_in_position():
    lead = 5e-3
    r = np.sin(2 * np.pi * 3 * X_REF / lead) + 0.1 * np.random.default_rng(0).normal(size=T.size)
    spec = order_spectrum(X_REF, V, r, lead)
    assert spec["peak_order"] == pytest.approx(3.0, abs=0.15)
    assert spec["peak_ratio"] > 10
    assert spec["n_segments"] == 2
    with pytest.raises(InputError):
        order_spectrum(X_REF, V, r, 0.0)


def test_order_spectrum_pools_runs_at_other_speeds_and_short_travels():
    """A residual fixed to the screw (order 12 of a 5 mm lead) on runs at 20 and 35 mm/s, each leg 6-10 mm of
    travel, shorter than the default segment of 8 leads: ``segment="auto"`` fits the segment to the stretches and
    the pooled spectrum peaks at order 12, while the two runs' time spectra peak 1.75 times apart."""
    lead, runs = 5e-3, []
    rng = np.random.default_rng(3)
    for speed in (0.02, 0.035):
        x = out_and_back(speed, 0.0, n=1000, leg=0.3, starts=(0.05, 0.5))
        v = np.gradient(x, 1e-3)
        runs.append((x, v, np.sin(2 * np.pi * 12 * x / lead) + 0.1 * rng.normal(size=x.size)))
    xs, vs, rs = (list(a) for a in zip(*runs))
    assert order_spectrum(xs, vs, rs, lead)["n_segments"] == 0  # 40 mm segments: no leg is that long
    spec = order_spectrum(xs, vs, rs, lead, segment="auto")
    assert spec["n_segments"] == 4
    assert abs(spec["peak_order"] - 12.0) <= spec["resolution"]
    assert spec["peak_ratio"] > 10
    # the share a flat spectrum would hold within a bin of the peak: three bins of those at orders >= 0.75
    assert spec["flat_share"] == pytest.approx(3 / np.count_nonzero(spec["orders"] >= 0.75))
    assert spec["peak_share"] > 2 * spec["flat_share"]
    peaks = [time_spectrum(r, 1e-3, nperseg=256)["peak_hz"] for r in rs]
    assert peaks[1] / peaks[0] == pytest.approx(1.75, rel=0.15)
    with pytest.raises(InputError):
        order_spectrum(xs, vs, rs, lead, segment="longest")


def test_time_spectrum_peak():
    r = np.sin(2 * np.pi * 40 * T)
    assert time_spectrum(r, 1e-3)["peak_hz"] == pytest.approx(40, abs=1.0)


def test_whiteness_separates_noise_from_structure():
    rng = np.random.default_rng(1)
    noise = rng.normal(size=2000)
    u = rng.normal(size=2000)
    assert whiteness(noise, u)["white"]
    coloured = np.convolve(noise, np.ones(10) / 10, mode="same")
    w = whiteness(coloured, u)
    assert not w["white"] and w["ljung_box_p"] < 1e-6
    correlated = 0.3 * noise + u  # white but driven by the input
    w2 = whiteness(correlated, u)
    assert w2["max_abs_xcorr"] > w2["xcorr_bound"] and not w2["white"]


def test_operating_map_bins_cover_the_energy():
    r = np.where(np.abs(V) > 0.04, 1.0, 0.0)
    m = operating_map(r, V, X_REF, V * 100, bins=4)
    assert sum(b["energy_share"] for b in m["speed"]) == pytest.approx(1.0)
    assert m["speed"][-1]["rms"] > m["speed"][0]["rms"]
    for rows in m.values():
        assert sum(b["time_share"] for b in rows) == pytest.approx(1.0)


def test_frequency_bands_find_a_30_hz_residual():
    from drakecreep.gap.residuals import frequency_bands

    rng = np.random.default_rng(0)
    t = np.arange(4000) * 1e-3
    r = np.sin(2 * np.pi * 30 * t) + 0.05 * rng.normal(size=t.size)
    out = frequency_bands([r[:2000], r[2000:]], 1e-3)
    assert out["top"]["lo_Hz"] == 10.0 and out["top"]["share"] > 0.9
    assert abs(out["peak_hz"] - 30.0) < 1.5
    assert abs(sum(b["share"] for b in out["bands"]) - 1.0) < 1e-9


def test_frequency_bands_end_at_the_nyquist_frequency():
    """A log every 4 ms ends at 125 Hz: the 50-150 Hz band ends there and the one from 150 Hz is left out (session
    86: a 4 ms EMPS log was reported with '50-125 Hz 3 %, 150-125 Hz 0 %')."""
    from drakecreep.gap.residuals import frequency_bands

    rng = np.random.default_rng(2)
    out = frequency_bands(rng.normal(size=2000), 4e-3)
    assert [(b["lo_Hz"], b["hi_Hz"]) for b in out["bands"]] == [(0.0, 2.0), (2.0, 10.0), (10.0, 50.0), (50.0, 125.0)]
    assert abs(sum(b["share"] for b in out["bands"]) - 1.0) < 1e-9
    assert [b["lo_Hz"] for b in frequency_bands(rng.normal(size=2000), 1e-3)["bands"]][-1] == 150.0


def test_independence_band_and_lag():
    from drakecreep.gap.residuals import independence

    rng = np.random.default_rng(1)
    u = np.convolve(rng.normal(size=5000), np.ones(5) / 5, mode="same")  # coloured input
    e_ind = np.convolve(rng.normal(size=5000), np.ones(5) / 5, mode="same")
    e_dep = 0.3 * np.roll(u, 3) + e_ind  # follows the input by 3 samples
    ind = independence(e_ind, {"u": u})["u"]
    dep = independence(e_dep, {"u": u})["u"]
    assert ind["independent"] and not dep["independent"]
    assert dep["lag_of_max"] == 3 and dep["max_abs"] > dep["band"]
    # Bartlett's band is wider than 2.58/sqrt(N) for coloured series
    assert ind["band"] > 2.58 / np.sqrt(5000)
    with pytest.raises(InputError):
        independence(e_ind[:50], {"u": u[:50]})


def test_motor_table_split():
    from drakecreep.gap.residuals import motor_table_split

    t = np.arange(3000) * 1e-3
    x = 0.01 * t
    sim = x.copy()
    after = motor_table_split(x, x + 2e-6 * np.sin(2 * np.pi * 3 * t), sim)
    before = motor_table_split(x + 2e-6 * np.sin(2 * np.pi * 3 * t), x + 2e-6 * np.sin(2 * np.pi * 3 * t), sim)
    assert after["where"] == "after the screw" and after["after_screw_share"] > 0.99
    assert before["where"] == "before the screw" and before["after_screw_share"] < 0.01


def _oscillating(freq=160.0, amp=50.0, n=2000, dt=1e-3, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    slow = 20.0 * np.sin(2 * np.pi * 0.5 * t)  # the motion's own force, well below 20 Hz
    return slow + amp * np.sin(2 * np.pi * freq * t + 0.3) + rng.normal(0.0, 1.0, n), slow + rng.normal(0.0, 1.0, n)


def test_dominant_oscillation_finds_a_limit_cycle_and_its_share():
    measured, quiet = _oscillating()
    o = dominant_oscillation(measured, 1e-3)
    assert abs(o["freq_Hz"] - 160.0) < 4.0
    assert o["rms"] == pytest.approx(50.0 / np.sqrt(2), rel=0.1)
    assert 0.75 < o["share"] < 0.9  # 1250 of 1250 + 200 + 1 N^2
    with pytest.raises(InputError, match="dt"):
        dominant_oscillation(measured, 0.0)
    with pytest.raises(InputError, match="f_min"):
        dominant_oscillation(measured, 1e-3, f_min=600.0)


def test_sustained_oscillation_only_when_the_replay_lacks_it_and_it_dominates():
    measured, quiet = _oscillating()
    o = sustained_oscillation([measured, measured], [quiet, quiet], 1e-3)
    assert o["runs"] == o["of"] == 2 and abs(o["freq_Hz"] - 160.0) < 4.0 and o["model_rms"] < 2.0
    assert o["freqs_Hz"] == [o["freq_Hz"]] * 2 and o["resolution_Hz"] == pytest.approx(1e3 / 256)
    assert sustained_oscillation([measured], [measured[::-1]], 1e-3) is None  # the replay oscillates too
    ripple, _ = _oscillating(freq=23.0, amp=5.0)  # a force ripple: 12.5 of 213 N^2, not a limit cycle
    assert sustained_oscillation([ripple], [quiet], 1e-3) is None
    assert sustained_oscillation([quiet], [quiet], 1e-3) is None
    with pytest.raises(InputError, match="simulated"):
        sustained_oscillation([measured], [], 1e-3)
    ok, osc = oscillates_at(measured, 1e-3, 150.0)
    assert ok and abs(osc["freq_Hz"] - 160.0) < 4.0
    assert not oscillates_at(measured, 1e-3, 100.0)[0] and not oscillates_at(quiet, 1e-3, 160.0)[0]


def test_oscillation_band_errors_score_the_runs_that_do_not_oscillate_too():
    """Two runs, the first oscillating at 160 Hz, the second quiet: a replay that oscillates on the first only scores
    about 0 nepers on both, one that oscillates on both is far off on the quiet run (judged in the band of the
    oscillation found on the other run), a quiet replay is far off on the oscillating one. sustained_oscillation
    says which run oscillates."""
    measured, quiet = _oscillating()
    shifted = quiet + (measured - quiet)[::-1]
    o = sustained_oscillation([measured, quiet], [quiet, quiet], 1e-3)
    assert o["runs"] == 1 and o["of"] == 2 and o["oscillating"] == [True, False]
    f = o["freq_Hz"]
    same = oscillation_band_errors([measured, quiet], [shifted, quiet[::-1]], 1e-3, f)
    everywhere = oscillation_band_errors([measured, quiet], [shifted, shifted], 1e-3, f)
    nowhere = oscillation_band_errors([measured, quiet], [quiet, quiet[::-1]], 1e-3, f)
    assert np.all(same < 0.2)
    assert everywhere[0] < 0.2 and everywhere[1] > np.log(10.0)
    assert nowhere[0] > np.log(10.0) and nowhere[1] < 0.2
    with pytest.raises(InputError, match="simulated"):
        oscillation_band_errors([measured], [], 1e-3, f)


def test_oscillation_log_errors_compare_the_band_rms_whatever_the_phase():
    """A replay of the same limit cycle with another phase scores about 0 nepers, one at half the amplitude
    ln 2, a stable one more than ln 10, one oscillating at another frequency as if stable."""
    measured, quiet = _oscillating()
    t = np.arange(measured.size) * 1e-3
    shifted = quiet + (measured - quiet)[::-1]  # the same oscillation, phase reversed in time
    half = quiet + 0.5 * (measured - quiet)
    elsewhere = quiet + 40.0 * np.sin(2 * np.pi * 90.0 * t)
    e = oscillation_log_errors([measured] * 4, [shifted, half, quiet, elsewhere], 1e-3)
    assert e[0] < 0.1 and abs(e[1] - np.log(2.0)) < 0.05 and e[2] > np.log(10.0) and e[3] > np.log(10.0)
    with pytest.raises(InputError, match="simulated"):
        oscillation_log_errors([measured], [], 1e-3)



def test_fixed_to_tells_a_force_fixed_to_the_travel_from_one_fixed_in_time():
    """Runs at 10, 20 and 30 mm/s, 1 s at constant speed each: a residual of 1 mm travel period peaks at 10, 20 and
    30 Hz (fixed to the travel, its period found), one at 25 Hz at 25 Hz in every run (fixed in time); runs at one
    speed cannot tell them apart, nor can noise alone be either."""
    from drakecreep.gap.residuals import fixed_to

    dt, rng = 1e-3, np.random.default_rng(5)
    t = np.arange(1000) * dt
    speeds = (0.01, 0.02, 0.03)
    labels = [np.array(["constant_speed"] * t.size)] * 3
    vs = [np.full(t.size, v) for v in speeds]
    travel = [np.sin(2 * np.pi * v * t / 1e-3) + 0.1 * rng.normal(size=t.size) for v in speeds]
    timed = [np.sin(2 * np.pi * 25.0 * t) + 0.1 * rng.normal(size=t.size) for _ in speeds]
    a = fixed_to(travel, vs, labels, dt)
    assert a["verdict"] == "travel" and a["period_m"] == pytest.approx(1e-3, rel=0.05)
    assert [r["peak_Hz"] for r in a["runs"]] == pytest.approx([10.0, 20.0, 30.0], abs=a["resolution_Hz"])
    assert fixed_to(timed, vs, labels, dt)["verdict"] == "time"
    same = [np.full(t.size, 0.02)] * 3
    assert fixed_to(timed, same, labels, dt)["verdict"] == "cannot tell"
    noise = [rng.normal(size=t.size) for _ in speeds]
    assert fixed_to(noise, vs, labels, dt)["verdict"] == "cannot tell"
    assert fixed_to(travel[:1], vs[:1], labels[:1], dt)["verdict"] == "cannot tell"  # one run says nothing


def test_limit_cycle_is_the_dominant_oscillation_when_it_holds_a_quarter_of_the_variance():
    from drakecreep.gap.residuals import OSCILLATION_SHARE, limit_cycle

    dt = 1e-3
    t = np.arange(3000) * dt
    rng = np.random.default_rng(0)
    cycle = 100.0 * np.sin(2 * np.pi * 207.0 * t) + rng.normal(0.0, 5.0, t.size)
    o = limit_cycle(cycle, dt)
    assert o is not None and abs(o["freq_Hz"] - 207.0) < 5.0 and o["share"] >= OSCILLATION_SHARE
    assert limit_cycle(rng.normal(0.0, 5.0, t.size), dt) is None  # noise: no line holds a quarter
    assert limit_cycle(cycle[:10], dt) is None  # too short to search: nothing to name
