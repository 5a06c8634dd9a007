"""Geodesy and rotations against pymap3d and closed form."""

from __future__ import annotations

import numpy as np
import pymap3d
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.geo import direction_angles, geodetic_to_ned, ned_rotation_to, ned_to_geodetic, rotation_matrix


@settings(max_examples=200, deadline=None)
@given(
    lat0=st.floats(-85, 85),
    lon0=st.floats(-180, 180),
    alt0=st.floats(-100, 3000),
    n=st.floats(-60_000, 60_000),
    e=st.floats(-60_000, 60_000),
    d=st.floats(-12_000, 500),
)
def test_single_point_ned_to_geodetic_matches_pymap3d(lat0, lon0, alt0, n, e, d):
    lat, lon, alt = ned_to_geodetic(np.array([n, e, d]), lat0, lon0, alt0)
    ref = pymap3d.ned2geodetic(n, e, d, lat0, lon0, alt0)
    assert float(lat) == pytest.approx(ref[0], abs=1e-9)
    assert np.angle(np.exp(1j * np.radians(float(lon) - ref[1]))) == pytest.approx(0.0, abs=1e-10)
    assert float(alt) == pytest.approx(ref[2], abs=1e-4)


def test_round_trip_arrays():
    rng = np.random.default_rng(0)
    ned = rng.uniform(-5000, 5000, (100, 3))
    lat, lon, alt = ned_to_geodetic(ned, 52.0, 4.0, 10.0)
    np.testing.assert_allclose(geodetic_to_ned(lat, lon, alt, 52.0, 4.0, 10.0), ned, atol=1e-6)


def test_scalar_rotation_matches_scipy_path():
    rng = np.random.default_rng(1)
    angles = rng.uniform(-3, 3, (20, 3))
    vectorised = rotation_matrix(angles[:, 0], angles[:, 1], angles[:, 2])
    for i, (yaw, pitch, roll) in enumerate(angles):
        np.testing.assert_allclose(rotation_matrix(yaw, pitch, roll), vectorised[i], atol=1e-12)


def test_ned_rotation_to_is_identity_at_origin_and_orthonormal():
    np.testing.assert_allclose(ned_rotation_to(52, 4, 52, 4), np.eye(3), atol=1e-12)
    r = ned_rotation_to(52, 4, 52.05, 4.07)
    np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)


def test_direction_angles():
    rng, az, el = direction_angles(np.array([[1.0, 1.0, -np.sqrt(2.0)]]))
    assert rng[0] == pytest.approx(2.0)
    assert az[0] == pytest.approx(np.pi / 4)
    assert el[0] == pytest.approx(np.pi / 4)
