"""Several radar heads, one tracker: the heads' detections as one stream in the aircraft's frame.

Each head measures range from its own antenna and the radial velocity along its own line of
sight. The lever arms are metres (wingtips 5 m from the centre line) against kilometres of range,
so a target's range seen from two heads differs by at most the lever arm (below the 15 m range
resolution) and its radial velocity by ``|lever arm| x rotation rate`` (centimetres per second in
a turn). The cleanest fusion is therefore one range-Doppler tracker over all heads, with each
detection's range referred to the aircraft reference point (the body-frame origin, where the
lever arms start): ``|p_body|`` where ``p_body = lever arm + range x direction`` is the
detection's body-frame position (``x/y/z_body_m``, which :mod:`skyradar.process` computes with
the lever arm). Its DoA position (``north/east/down_m``) is already in the world frame, so the
3-D tracker needs nothing more. A target crossing from one head's beam into the next then stays
in one track (a handover is nothing but the next detection of the same track).

Where two beams overlap, one aircraft gives a detection in each head in the same frame. Only
the strongest of them is kept (:func:`fuse_heads`): two detections of one frame from different
heads are one object when their ranges (referred to the reference point) differ by at most
``range_gate_bins`` range resolutions, their radial velocities (modulo the Doppler width) by at
most ``doppler_gate_bins`` Doppler resolutions, and, with DoA positions, their positions by at
most ``position_gate`` times the range (angle errors of a 2x2 array at low SNR are tenths of a
radian). Two aircraft that agree in all three in one frame are merged for that frame, which
costs the weaker one an update (a miss), not its track.

The position gate holds only while the weaker detection's direction means something. Each
head's field of view ends where its pattern is :data:`~skyradar.process.doa.FIELD_OF_VIEW_LOSS_DB`
(6 dB) below its peak one-way, and its DoA search covers no more. A target inside both heads'
fields gives SNRs at most twice that apart (12 dB, two-way: the same target, range and
fluctuation in both). A weaker detection further below is the target seen from outside the weaker
head's field, through its pattern's skirts, where its direction search cannot point at it (a wing
head sees an aircraft ahead of the nose 30 dB below the nose head, its azimuths scattered over
+-90 deg): it is a duplicate whatever its position says. The cost is the same as above: a second
aircraft at the same range and radial velocity, that much weaker, loses that frame's update.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from skyradar.config import RadarConfig
from skyradar.process.doa import FIELD_OF_VIEW_LOSS_DB

__all__ = ["fuse_heads", "restore_detection_rows", "HEAD_COLUMN"]

HEAD_COLUMN = "radar"  # the detections column naming the radar head (skyradar.process.detect_run)
_BODY = ("x_body_m", "y_body_m", "z_body_m")
_NED = ("north_m", "east_m", "down_m")
# SNR gap beyond which the weaker of two heads sees a target from outside its field of view, dB
OUTSIDE_FIELD_GAP_DB = 2.0 * FIELD_OF_VIEW_LOSS_DB


def _duplicates(r, v, pos, heads, snr, width: float, gates: tuple[float, float, float]) -> np.ndarray:
    """Within one frame: True for detections another head saw more strongly (greedy, by SNR)."""
    order = np.argsort(-snr, kind="stable")
    kept: list[int] = []
    dup = np.zeros(r.size, bool)
    gate_r, gate_v, gate_p = gates
    for i in order:
        for j in kept:
            if heads[i] == heads[j] or abs(r[i] - r[j]) > gate_r:
                continue
            dv = v[i] - v[j]
            if abs(dv - width * np.round(dv / width)) > gate_v:
                continue
            apart = pos is not None and np.linalg.norm(pos[i] - pos[j]) > gate_p * max(r[i], 1.0)
            if apart and snr[j] - snr[i] <= OUTSIDE_FIELD_GAP_DB:
                continue
            dup[i] = True
            break
        if not dup[i]:
            kept.append(i)
    return dup


def _reference_range(det: pd.DataFrame) -> np.ndarray:
    """Range from the aircraft reference point, |body-frame position|; the head's where unknown."""
    r = det["range_m"].to_numpy(float).copy()
    if all(c in det.columns for c in _BODY):
        body = det[list(_BODY)].to_numpy(float)
        ok = np.all(np.isfinite(body), axis=1)
        r[ok] = np.linalg.norm(body[ok], axis=1)
    return r


def fuse_heads(
    detections: pd.DataFrame,
    config: RadarConfig | None = None,
    range_gate_bins: float = 2.0,
    doppler_gate_bins: float = 2.0,
    position_gate: float = 0.3,
    several_heads: bool | None = None,
) -> tuple[pd.DataFrame, np.ndarray | None]:
    """One world-frame detection stream from several heads' detections (see the module docstring).

    Parameters
    ----------
    detections : DataFrame
        A detections table in time order with a ``radar`` column (head name). Without it, or with
        one head only, the table is returned unchanged.
    config : RadarConfig, optional
        Range and Doppler resolution and Doppler width of the heads (default: thesis prototype;
        the heads share that hardware for one tracker).
    range_gate_bins, doppler_gate_bins, position_gate : float
        Same-frame duplicate gates (range and Doppler resolutions; fraction of the range).
    several_heads : bool, optional
        Whether the detections come from more than one head; None: the ``radar`` column says so.
        A stream fusing one frame at a time passes its chain's head count: a frame seen by one head
        only is still referred to the reference point.

    Returns
    -------
    (fused, rows)
        ``fused``: the kept detections in time order, ``range_m`` referred to the aircraft
        reference point (the head's own range in ``head_range_m``); ``rows``: for each fused row its
        row in ``detections`` (None when nothing was fused).

    Examples
    --------
    >>> det = pd.DataFrame({"time_s": [0.0, 0.0, 0.1], "range_m": [1000.0, 1003.0, 995.0],
    ...     "radial_velocity_mps": [-20.0, -20.1, -20.0], "snr_db": [20.0, 25.0, 22.0],
    ...     "radar": ["nose", "left", "left"]})
    >>> fused, rows = fuse_heads(det)
    >>> rows.tolist(), fused["radar"].tolist()
    ([1, 2], ['left', 'left'])
    """
    if several_heads is None:
        several_heads = HEAD_COLUMN in detections.columns and detections[HEAD_COLUMN].nunique() > 1
    if not several_heads or HEAD_COLUMN not in detections.columns:
        return detections, None
    config = config or RadarConfig.prototype_2022()
    det = detections.reset_index(drop=True)
    r = _reference_range(det)
    v = det["radial_velocity_mps"].to_numpy(float)
    pos = det[list(_NED)].to_numpy(float) if all(c in det.columns for c in _NED) else None
    snr = det["snr_db"].to_numpy(float) if "snr_db" in det.columns else np.zeros(len(det))
    heads = det[HEAD_COLUMN].astype(str).to_numpy()
    gates = (
        range_gate_bins * config.range_resolution_m,
        doppler_gate_bins * config.doppler_resolution_mps,
        position_gate,
    )
    times = det["time_s"].to_numpy(float)
    dup = np.zeros(len(det), bool)
    # Secondary rows (gate-only candidates, skyradar.track.tracker) are kept as they are: a track
    # takes at most one detection per frame, primary ones first, and the rest start nothing.
    primary = ~det["secondary"].fillna(False).to_numpy(bool) if "secondary" in det.columns else None
    _, start, count = np.unique(times, return_index=True, return_counts=True)
    for a, n in zip(start, count, strict=True):
        sl = np.arange(a, a + n) if primary is None else a + np.flatnonzero(primary[a : a + n])
        if sl.size > 1:
            p = None if pos is None else pos[sl]
            dup[sl] = _duplicates(r[sl], v[sl], p, heads[sl], snr[sl], 2.0 * config.v_lim_mps, gates)
    rows = np.flatnonzero(~dup)
    fused = det.iloc[rows].assign(head_range_m=det["range_m"].to_numpy(float)[rows], range_m=r[rows])
    return fused.reset_index(drop=True), rows


def restore_detection_rows(tracks: pd.DataFrame, rows: np.ndarray | None) -> pd.DataFrame:
    """Tracks whose ``detection_row`` indexes the fused table, re-pointed at the input table's rows.

    Examples
    --------
    >>> tracks = pd.DataFrame({"detection_row": [0, -1, 1]})
    >>> restore_detection_rows(tracks, np.array([1, 2]))["detection_row"].tolist()
    [1, -1, 2]
    """
    if rows is None or len(tracks) == 0:
        return tracks
    det = tracks["detection_row"].to_numpy()
    mapped = np.where(det >= 0, rows[np.clip(det, 0, max(rows.size - 1, 0))], -1) if rows.size else det
    return tracks.assign(detection_row=mapped.astype(np.int64))
