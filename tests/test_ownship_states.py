"""The own-ship state object: built from a frames run as the navigation reader gives it, validated,
selected and joined, and the DAA's interpolation of an own-ship table into it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from skyradar.daa.tables import interp_ownship
from skyradar.io.navigation import STATE_COLUMNS, navigation_state
from skyradar.io.ownship_states import REQUIRED_COLUMNS, OwnShipStates
from skyradar.process.pipeline import navigated_own_state

_KINEMATIC = ("north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps")


def _run(prefix: str, names: tuple[str, ...], n: int = 5, seed: int = 0) -> xr.Dataset:
    """A frames-like Dataset with variables ``prefix + name`` of random values on ``time``."""
    rng = np.random.default_rng(seed)
    data = {prefix + name: ("time", rng.normal(0.0, 100.0, n)) for name in names}
    return xr.Dataset(data, coords={"time": np.arange(n) * 0.1})


def _reference(ds: xr.Dataset) -> dict:
    """Peer: the per-frame state by the navigation reader's columns, filled as the pipeline documents
    (attitude and geodetic fix 0 when absent, height above ground NaN)."""
    nav = navigation_state(ds)
    assert nav is not None
    out = {"time_s": nav["time_s"].to_numpy(float)}
    for name in STATE_COLUMNS:
        fill = np.nan if name == "own_height_agl_m" else 0.0
        out[name[4:]] = nav[name].to_numpy(float) if name in nav else np.full(len(nav), fill)
    out["has_geo"] = all(f"own_{k}" in nav for k in ("lat_deg", "lon_deg", "alt_m"))
    out["navigation_source"] = nav.attrs["navigation_source"]
    return out


@pytest.mark.parametrize(
    "prefix, names",
    [
        ("nav_", tuple(c[4:] for c in STATE_COLUMNS)),  # a full navigation solution
        ("nav_", _KINEMATIC),  # position and velocity only
        ("own_", _KINEMATIC + ("yaw_rad", "lat_deg", "lon_deg", "alt_m")),  # a store without navigation
        ("nav_", _KINEMATIC + ("lat_deg", "lon_deg")),  # a partial fix is no fix
    ],
)
def test_from_frames_holds_the_navigation_readers_values_exactly(prefix, names):
    ds = _run(prefix, names)
    own = OwnShipStates.from_frames(ds)
    assert own is not None and len(own) == ds.sizes["time"]
    want = _reference(ds)
    for field in dataclasses.fields(OwnShipStates):
        got = getattr(own, field.name)
        if isinstance(got, np.ndarray):
            assert got.dtype == np.float64 and not got.flags.writeable
            np.testing.assert_array_equal(got, want[field.name], err_msg=field.name)
        else:
            assert got == want[field.name], field.name
    assert own.navigation_source == ("navigation" if prefix == "nav_" else "truth")
    assert navigated_own_state(ds) is not None


def test_from_frames_is_none_without_position_and_velocity():
    assert OwnShipStates.from_frames(xr.Dataset(coords={"time": [0.0]})) is None
    assert OwnShipStates.from_frames(_run("nav_", ("north_m", "east_m", "down_m"))) is None


def _columns(n: int) -> dict:
    return {name: np.arange(n, dtype=float) + k for k, name in enumerate(REQUIRED_COLUMNS)}


def test_the_arrays_must_be_one_dimensional_and_equally_long():
    OwnShipStates.from_columns(_columns(3))
    with pytest.raises(ValueError, match="'north_m' has 2 values"):
        OwnShipStates.from_columns(_columns(3) | {"own_north_m": np.zeros(2)})
    with pytest.raises(ValueError, match="one-dimensional"):
        OwnShipStates.from_columns(_columns(3) | {"own_yaw_rad": np.zeros((3, 1))})
    with pytest.raises(ValueError, match="navigation_source"):
        OwnShipStates.from_columns(_columns(3), navigation_source="gnss")  # type: ignore[arg-type]
    with pytest.raises(KeyError, match="own_vd_mps"):
        OwnShipStates.from_columns({k: v for k, v in _columns(3).items() if k != "own_vd_mps"})


def test_a_state_never_changes_under_its_consumers():
    source = np.zeros(3)
    own = OwnShipStates.from_columns(_columns(3) | {"own_north_m": source})
    source[0] = 7.0  # the caller's array is copied
    assert own.north_m[0] == 0.0
    with pytest.raises(ValueError):
        own.north_m[0] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        own.has_geo = True  # type: ignore[misc]


def test_select_slices_masks_and_single_frames_keep_every_field_and_the_flags():
    geo = {"own_lat_deg": np.full(4, 52.0), "own_lon_deg": np.full(4, 4.0), "own_alt_m": np.full(4, 300.0)}
    own = OwnShipStates.from_columns(_columns(4) | geo, navigation_source="navigation")
    mask = np.array([True, False, True, False])
    for index, rows in ((slice(1, 3), [1, 2]), (mask, [0, 2]), (np.array([3, 0]), [3, 0]), (2, [2])):
        part = own.select(index)
        assert len(part) == len(rows) and part.has_geo and part.navigation_source == "navigation"
        for name in ("time_s", "north_m", "vd_mps", "lat_deg", "height_agl_m"):
            np.testing.assert_array_equal(getattr(part, name), getattr(own, name)[rows])
    np.testing.assert_array_equal(own[1:].time_s, own.time_s[1:])
    np.testing.assert_array_equal(own.position_ned_m, np.column_stack([own.north_m, own.east_m, own.down_m]))
    np.testing.assert_array_equal(own.velocity_ned_mps, np.column_stack([own.vn_mps, own.ve_mps, own.vd_mps]))


def test_concatenate_joins_in_order_with_the_newest_flags():
    first = OwnShipStates.from_columns(_columns(2), navigation_source="truth")
    second = OwnShipStates.from_columns(_columns(3), navigation_source="navigation")
    both = OwnShipStates.concatenate([first, second])
    np.testing.assert_array_equal(both.time_s, np.r_[first.time_s, second.time_s])
    np.testing.assert_array_equal(both.height_agl_m, np.r_[first.height_agl_m, second.height_agl_m])
    assert both.navigation_source == "navigation" and len(both) == 5
    with pytest.raises(ValueError, match="no states"):
        OwnShipStates.concatenate([])


def test_interp_ownship_interpolates_every_column_and_fills_the_rest():
    t = np.array([0.0, 1.0, 2.0, 3.0])
    table = pd.DataFrame({"time_s": t[::-1]})  # unsorted on purpose: interpolation sorts
    rng = np.random.default_rng(3)
    for name in REQUIRED_COLUMNS[1:]:
        table[name] = rng.normal(0.0, 50.0, t.size)
    table["own_yaw_rad"] = [3.0, -3.1, 3.1, -3.0]  # wraps: interpolated unwrapped
    table.attrs["navigation_source"] = "navigation"
    at = np.array([0.25, 1.5, 2.9])
    got = interp_ownship(table, at, "tracks")
    ordered = table.sort_values("time_s")
    for name in REQUIRED_COLUMNS[1:]:
        np.testing.assert_array_equal(getattr(got, name[4:]), np.interp(at, t, ordered[name].to_numpy()))
    yaw = np.interp(at, t, np.unwrap(ordered["own_yaw_rad"].to_numpy()))
    np.testing.assert_array_equal(got.yaw_rad, yaw)
    np.testing.assert_array_equal(got.time_s, at)
    assert np.isnan(got.height_agl_m).all() and not got.has_geo and got.navigation_source == "navigation"
    # Without a heading: the ground track.
    got = interp_ownship(table.drop(columns="own_yaw_rad"), at, "tracks")
    np.testing.assert_array_equal(got.yaw_rad, np.arctan2(got.ve_mps, got.vn_mps))
