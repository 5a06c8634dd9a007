"""Passive-radar illuminator, scene and IQ simulator against closed forms and peers.

Expected values come from formulas written out here (Friis, the bistatic radar equation, bistatic
geometry from pymap3d positions) or from scipy, never from the simulator's own helpers.
"""

from __future__ import annotations

import dataclasses
import math
import tracemalloc

import numpy as np
import pymap3d
import pytest
import scipy.signal
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.errors import InputError
from skyradar.passive.illuminator import Illuminator, lfm_baseband
from skyradar.passive.scene import Aircraft, Reflectors, aircraft_from_adsb, thesis_scene
from skyradar.passive.simulate import simulate_chunk, simulate_recording
from skyradar.passive.truth import truth_table
from skyradar.scene.trajectories import Trajectory

C = 299_792_458.0
FS = 5e6


def _scene(reflectors=None, aircraft=(), beam_at=None, duration_s=0.02):
    """The thesis sites with the given reflectors; the beam at t=0 points at ``beam_at`` (NED) if given."""
    base = thesis_scene(duration_s=duration_s, aircraft=False)
    refl = reflectors or Reflectors(np.zeros((0, 3)), np.zeros(0), np.zeros(0, object), np.zeros(0, object))
    scene = dataclasses.replace(base, reflectors=refl, aircraft=tuple(aircraft))
    if beam_at is not None:
        az = float(scene.azimuth_from_tx_rad(np.asarray(beam_at, float).reshape(1, 3))[0])
        scene = dataclasses.replace(scene, azimuth_at_t0_rad=az)
    return scene


def _tx_ned(scene):
    ill, rx = scene.illuminator, scene.receiver
    return np.array(pymap3d.geodetic2ned(ill.latitude, ill.longitude, ill.altitude, *rx.geodetic))


def _template(t_s, ill):
    """Long pulse written out: phase 2 pi ((fo - B/2) t + B t^2 / (2 T))."""
    p = ill.long_pulse
    f0, k = p.offset_hz - p.bandwidth_hz / 2, p.bandwidth_hz / p.width_s
    inside = (t_s >= 0) & (t_s < p.width_s)
    return np.where(inside, np.exp(2j * np.pi * (f0 * t_s + 0.5 * k * t_s**2)), 0)


def test_lfm_matches_scipy_chirp():
    t = np.arange(500) / FS
    ours = lfm_baseband(t, 100e-6, 1.5e6, -0.9e6)
    peer = scipy.signal.chirp(t, f0=-1.65e6, t1=100e-6, f1=-0.15e6, method="linear")
    np.testing.assert_allclose(ours.real, peer, atol=2e-4)


def test_pattern_and_timing():
    ill = Illuminator(52.0, 5.0, 20.0)
    assert ill.pattern_gain(np.radians(0.7)) == pytest.approx(0.5, rel=1e-3)  # 3 dB beamwidth 1.4 deg
    assert 10 * np.log10(ill.pattern_gain(np.pi)) == pytest.approx(ill.backlobe_db)
    assert np.all(np.diff(ill.pattern_gain(np.radians(np.linspace(0, 180, 2000)))) <= 1e-15)
    _, t = ill.pulse_times_s(0.0, 0.0, 0.0101)
    np.testing.assert_allclose(np.diff(t)[:4], ill.pri_s)
    assert 9 * ill.rotation_period_s == pytest.approx(40.0)


def test_direct_path_power_is_friis_in_the_main_beam_and_floor_in_the_back_lobe():
    scene = _scene(beam_at=[0.0, 0.0, 0.0])  # the beam points at the receiver at t=0
    ill, rx = scene.illuminator, scene.receiver
    x = simulate_chunk(scene, FS, 0, int(0.02 * FS), noise=False)
    lam, L = C / ill.carrier_frequency_hz, float(np.linalg.norm(_tx_ned(scene)))
    friis = (
        ill.peak_power_w
        * 10 ** ((ill.antenna_gain_dbi + rx.antenna_gain_dbi) / 10)
        * lam**2
        / ((4 * np.pi) ** 2 * L**2)
    )
    t0 = scene.first_pulse_s + L / C  # first long pulse's arrival
    off_deg = math.degrees(ill.rotation_rate_rad_s * scene.first_pulse_s)
    mainlobe = math.exp(-4 * math.log(2) * (off_deg / 1.4) ** 2)
    n = int(math.ceil(t0 * FS)) + 5
    assert np.mean(np.abs(x[n : n + 400]) ** 2) == pytest.approx(friis * mainlobe, rel=1e-6)
    # A quarter turn later the receiver is in the back lobe (-35 dB).
    scene = dataclasses.replace(scene, azimuth_at_t0_rad=scene.azimuth_at_t0_rad + np.pi / 2)
    y = simulate_chunk(scene, FS, 0, int(0.02 * FS), noise=False)
    assert np.mean(np.abs(y[n : n + 400]) ** 2) == pytest.approx(friis * 10 ** (-3.5), rel=1e-3)


def test_static_echo_is_the_bistatic_radar_equation_at_the_bistatic_delay():
    p = np.array([9000.0, 6000.0, 30.0])
    rcs = 50.0
    refl = Reflectors(p[None, :], [rcs], ["building"], ["one"])
    scene = _scene(refl, beam_at=p)
    n = int(0.004 * FS)
    echo = simulate_chunk(scene, FS, 0, n, noise=False) - simulate_chunk(
        _scene(beam_at=p), FS, 0, n, noise=False
    )
    ill, rx = scene.illuminator, scene.receiver
    tx = _tx_ned(scene)
    r_tx, r_rx = np.linalg.norm(p - tx), np.linalg.norm(p)
    lam = C / ill.carrier_frequency_hz
    t = np.arange(n) / FS
    expected = np.zeros(n, complex)
    for te in (scene.first_pulse_s, scene.first_pulse_s + ill.pri_s[0]):  # the first two PRIs' long pulses
        off = math.degrees(ill.rotation_rate_rad_s * te)
        g = math.exp(-4 * math.log(2) * (off / 1.4) ** 2)
        power = (
            ill.peak_power_w * 10 ** ((ill.antenna_gain_dbi + rx.antenna_gain_dbi) / 10) * g * lam**2 * rcs
        )
        power /= (4 * np.pi) ** 3 * r_tx**2 * r_rx**2
        tau = (r_tx + r_rx) / C
        expected += (
            math.sqrt(power)
            * np.exp(-2j * np.pi * ill.carrier_frequency_hz * tau)
            * _template(t - te - tau, ill)
        )
    window = slice(
        0, int((scene.first_pulse_s + 2 * ill.pri_s[0] - 5e-6) * FS)
    )  # short pulses excluded below
    keep = np.abs(expected[window]) > 0
    np.testing.assert_allclose(
        echo[window][keep], expected[window][keep], rtol=1e-6, atol=1e-12 * np.abs(expected).max()
    )
    # The excess delay over the direct path is the bistatic range / c.
    mf = np.abs(np.correlate(echo[: window.stop], _template(np.arange(500) / FS, ill), mode="valid"))
    peak = int(np.argmax(mf))
    assert abs(peak / FS - scene.first_pulse_s - (r_tx + r_rx) / C) < 1.0 / FS


def test_aircraft_echo_phase_follows_the_bistatic_doppler():
    v = np.array([30.0, -40.0, 0.0])
    p0 = np.array([1500.0, 500.0, -400.0])
    t = np.array([-1.0, 1.0])
    traj = Trajectory.from_states(
        t, p0 + t[:, None] * v, np.tile(v, (2, 1)), origin=thesis_scene().receiver.geodetic
    )
    scene = _scene(aircraft=[Aircraft(traj, 1.0)], beam_at=p0, duration_s=0.035)
    n = int(0.035 * FS)
    echo = simulate_chunk(scene, FS, 0, n, noise=False) - simulate_chunk(
        _scene(beam_at=p0), FS, 0, n, noise=False
    )
    ill, tx = scene.illuminator, _tx_ned(scene)
    _, t_pri = ill.pulse_times_s(scene.first_pulse_s, 0.0, 0.03)
    ts = np.arange(n) / FS
    phases, taus = [], []
    for te in t_pri:
        tb = te
        for _ in range(3):  # the bounce: the pulse leaves at te and meets the aircraft at tb
            tb = te + np.linalg.norm(p0 + tb * v - tx) / C
        pos = p0 + tb * v
        tau = (np.linalg.norm(pos - tx) + np.linalg.norm(pos)) / C
        taus.append(tau)
        win = slice(int(te * FS), int((te + tau + 2e-4) * FS))
        phases.append(np.angle(np.vdot(_template(ts[win] - te - tau, ill), echo[win])))
    predicted = -2 * np.pi * ill.carrier_frequency_hz * np.diff(taus)
    measured = np.diff(phases)
    np.testing.assert_allclose(np.angle(np.exp(1j * (measured - predicted))), 0.0, atol=0.01)
    # and the rate is the closed-form bistatic Doppler -(v.u_tx + v.u_rx) / lambda
    u_tx, u_rx = (p0 - tx) / np.linalg.norm(p0 - tx), p0 / np.linalg.norm(p0)
    doppler = -(v @ u_tx + v @ u_rx) / (C / ill.carrier_frequency_hz)
    slope = np.polyfit(t_pri, np.unwrap(phases), 1)[0] / (2 * np.pi)
    assert slope == pytest.approx(doppler, abs=1.0)


def test_chunked_recording_equals_one_shot_and_sigmf_round_trip(tmp_path):
    import sigmf

    from skyradar.io.sigmf_io import read_iq_recording

    scene = thesis_scene(duration_s=0.03)
    one = simulate_recording(scene, tmp_path / "one.sigmf-meta", chunk_samples=1 << 20)
    many = simulate_recording(scene, tmp_path / "many", chunk_samples=12_345)
    a, b = read_iq_recording(one), read_iq_recording(many)
    assert a.n_samples == b.n_samples == int(0.03 * FS)
    x, y = a.read(0, a.n_samples), b.read(0, b.n_samples)
    np.testing.assert_allclose(x, y, rtol=1e-5, atol=1e-6 * np.abs(x).std())
    handle = sigmf.fromfile(str(one))  # verifies core:sha512 against the data
    handle.validate()
    np.testing.assert_array_equal(handle.read_samples(), x)
    np.testing.assert_array_equal(np.concatenate([c for _, c in a.chunks(7000, 0)]), x)
    direct = simulate_chunk(scene, FS, 1000, 3000).astype(np.complex64)
    np.testing.assert_array_equal(a.read(1000, 2000), direct)
    assert a.illuminator_geodetic == pytest.approx(
        (scene.illuminator.latitude, scene.illuminator.longitude, scene.illuminator.altitude)
    )
    assert a.receiver_geodetic == pytest.approx(scene.receiver.geodetic)
    assert a.truth_table_path is not None and a.truth_json_path is not None


def test_simulation_memory_is_bounded_by_the_chunk(tmp_path):
    scene = thesis_scene(duration_s=0.1)
    peaks = []
    for duration in (0.02, 0.1):
        s = dataclasses.replace(scene, duration_s=duration)
        simulate_chunk(s, FS, 0, 10)  # compile and warm caches outside the measurement
        tracemalloc.start()
        # one worker: two threads overlap their temporaries at random, which would make the peak noisy
        simulate_recording(s, tmp_path / f"r{duration}.sigmf-meta", chunk_samples=1 << 14, workers=1)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    assert peaks[1] < 1.3 * peaks[0]  # five times the samples, the same working set
    assert peaks[1] < 40 * (1 << 14) * 16  # a few chunk-sized buffers
    from skyradar.io.sigmf_io import read_iq_recording

    rec = read_iq_recording(tmp_path / "r0.1.sigmf-meta")
    tracemalloc.start()
    total = sum(float(np.abs(chunk).sum()) for _, chunk in rec.chunks(1 << 14, overlap=500))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert total > 0 and peak < 4 * ((1 << 14) + 500) * 8  # reading holds about one chunk too


def test_truth_rows_sit_where_the_beam_points():
    scene = thesis_scene()
    truth = truth_table(scene)
    plane = truth[truth.kind == "aircraft"]
    assert plane.sweep.tolist() == list(range(9))
    assert plane.r_rx_m.between(1000, 3000).all()
    clusters = truth[truth.kind == "building"].groupby("name").r_rx_m.median()
    assert clusters.between(14_000, 20_000).all() and len(clusters) == 5
    beam = scene.illuminator.beam_azimuth_rad(truth.time_s.to_numpy(), scene.azimuth_at_t0_rad)
    off = np.angle(np.exp(1j * (beam - np.radians(truth.azimuth_from_tx_deg.to_numpy()))))
    assert np.abs(off).max() < 1e-6


def test_aircraft_from_an_adsb_file_is_placed_in_the_receiver_frame(tmp_path):
    import datetime as dt

    scene = thesis_scene(aircraft=False)
    f = tmp_path / "adsb.csv"
    f.write_text(
        "timestamp,icao24,latitude,longitude,altitude\n"
        "1780308000,abc123,52.11,5.30,1500\n1780308010,abc123,52.111,5.301,1500\n"
    )
    start = dt.datetime.fromtimestamp(1780308005, dt.UTC)
    (plane,) = aircraft_from_adsb(f, scene.receiver, start_time=start)
    present, pos, _ = plane.states(np.array([-5.0, 0.0, 6.0]))
    assert present.tolist() == [True, True, False]
    expected = pymap3d.geodetic2ned(52.11, 5.30, 1500 * 0.3048, *scene.receiver.geodetic)
    np.testing.assert_allclose(pos[0], expected, atol=0.5)


@given(
    first=st.floats(-0.01, 0.01),
    a=st.floats(-0.05, 0.05),
    split=st.floats(0.0, 0.02),
    length=st.floats(0.0, 0.02),
)
@settings(max_examples=60, deadline=None)
def test_pulse_schedule_splits_exactly_at_any_chunk_boundary(first, a, split, length):
    ill = Illuminator(52.0, 5.0, 20.0)
    b, c = a + split, a + split + length
    k_ab, t_ab = ill.pulse_times_s(first, a, b)
    k_bc, t_bc = ill.pulse_times_s(first, b, c)
    k_ac, t_ac = ill.pulse_times_s(first, a, c)
    assert np.concatenate([k_ab, k_bc]).tolist() == k_ac.tolist()
    np.testing.assert_array_equal(np.concatenate([t_ab, t_bc]), t_ac)
    assert np.all((t_ac >= a) & (t_ac < c)) and np.all(np.diff(k_ac) == 1)
    # pulse k starts where the stagger cycle puts it
    cycle_start = first + (k_ac // 4) * sum(ill.pri_s)
    within = np.concatenate([[0.0], np.cumsum(ill.pri_s)[:-1]])[k_ac % 4]
    np.testing.assert_allclose(t_ac, cycle_start + within, atol=1e-12)


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        ({"rotation_rpm": "fast"}, "'rotation_rpm' must be a finite number"),
        ({"long_pulse": "x"}, "'long_pulse' must be an object"),
        ({"long_pulse": {"width_s": 2e-3}}, "must fit the shortest PRI"),
        ({"pri_s": []}, "'pri_s' is empty"),
        ({"rotation_direction": "anticlockwise"}, "only 'clockwise'"),
    ],
)
def test_illuminator_metadata_errors_name_the_field(change, needle):
    meta = Illuminator(52.0, 5.0, 20.0).to_metadata()
    assert Illuminator.from_metadata(meta) == Illuminator(52.0, 5.0, 20.0)
    with pytest.raises(InputError, match=needle):
        Illuminator.from_metadata({**meta, **change})
