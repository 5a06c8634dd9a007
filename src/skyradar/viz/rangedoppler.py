"""Range-Doppler figures: strength in dB and phase difference between two receive antennas.

Images are drawn with pixel edges on the true bin edges (range ``k*dR +- dR/2``, radial
velocity ``(j - nV/2)*dV +- dV/2``), radial velocity on x and range on y as in the thesis.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from skyradar.config import RadarConfig  # noqa: E402
from skyradar.io.atomic import savefig_atomic  # noqa: E402
from skyradar.process.power import power_image  # noqa: E402

__all__ = ["image_extent", "plot_strength", "plot_phase_difference", "save_frame_figure"]


def image_extent(config: RadarConfig) -> tuple[float, float, float, float]:
    """(left, right, bottom, top) of the image in (m/s, m) on bin edges.

    Parameters
    ----------
    config : RadarConfig
        The radar: its range and Doppler axes and resolutions.

    Returns
    -------
    (float, float, float, float)
        Radial velocity from half a bin below the first to half a bin above the last (m/s), range
        likewise (m): the image spans ``n_doppler`` velocity bins by ``n_range`` range bins.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> left, right, bottom, top = image_extent(cfg)
    >>> height = cfg.n_range * cfg.range_resolution_m
    >>> round(float(bottom), 4), round(float(top), 4), round(float(bottom + height), 4)
    (-7.4948, 4984.0496, 4984.0496)
    >>> bool(np.isclose(right - left, cfg.n_doppler * cfg.doppler_resolution_mps))
    True
    """
    dv, dr = config.doppler_resolution_mps, config.range_resolution_m
    v, r = config.doppler_axis_mps, config.range_axis_m
    return (v[0] - dv / 2, v[-1] + dv / 2, r[0] - dr / 2, r[-1] + dr / 2)


def strength_db(frame: np.ndarray, config: RadarConfig) -> np.ndarray:
    """Channel-mean power (:func:`skyradar.process.power.power_image`), dB over the per-pixel noise power."""
    power = power_image(frame, dtype=np.float64)
    return 10 * np.log10(np.maximum(power, 1e-30) / config.noise_power_w)


def plot_strength(
    frame: np.ndarray, config: RadarConfig, ax=None, vmin: float = -5.0, vmax: float | None = None
):
    """Strength image (dB over noise) of one (range, doppler, rx) frame.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> im = plot_strength(np.ones((cfg.n_range, cfg.n_doppler, cfg.n_rx)) * 1e-9, cfg)
    >>> bool(im.get_extent()[0] < 0 < im.get_extent()[1])
    True
    >>> plt.close(im.figure)
    """
    ax = ax or plt.gca()
    db = strength_db(frame, config)
    vmax = float(np.percentile(db, 99.95)) if vmax is None else vmax
    im = ax.imshow(
        db, origin="lower", aspect="auto", extent=image_extent(config), cmap="viridis", vmin=vmin, vmax=vmax
    )
    ax.set_xlabel("radial velocity [m/s]")
    ax.set_ylabel("range [m]")
    plt.colorbar(im, ax=ax, label="strength over noise [dB]")
    return im


def plot_phase_difference(
    frame: np.ndarray, config: RadarConfig, rx_pair: tuple[int, int] = (0, 1), ax=None, min_db: float = 6.0
):
    """Phase of rx_pair[1] relative to rx_pair[0] (degrees), pixels below ``min_db`` blanked.

    Parameters
    ----------
    frame : ndarray
        One frame, (range, doppler, rx), complex.
    config : RadarConfig
        The radar (axes and noise power).
    rx_pair : (int, int)
        The reference receiver and the one whose phase is shown.
    ax : matplotlib Axes, optional
        Where to draw; default the current axes.
    min_db : float
        Pixels whose strength (:func:`plot_strength`'s, dB over noise) is below this are blank.

    Returns
    -------
    matplotlib.image.AxesImage
        The image (with its colour bar).

    Examples
    --------
    Every pixel 20 dB over noise, rx1 a quarter turn ahead of rx0:

    >>> cfg = RadarConfig.prototype_2022()
    >>> frame = np.full((cfg.n_range, cfg.n_doppler, cfg.n_rx), np.sqrt(100 * cfg.noise_power_w), complex)
    >>> frame[..., 1] *= 1j
    >>> fig, ax = plt.subplots()
    >>> im = plot_phase_difference(frame, cfg, ax=ax)
    >>> float(np.nanmax(im.get_array())), ax.get_ylabel(), im.colorbar.ax.get_ylabel()
    (90.0, 'range [m]', 'phase rx1 - rx0 [deg]')
    >>> im = plot_phase_difference(frame, cfg, ax=ax, min_db=30.0)  # all below 30 dB: blank
    >>> int(im.get_array().count())  # pixels shown
    0
    >>> plt.close(fig)
    """
    ax = ax or plt.gca()
    a, b = rx_pair
    phase = np.degrees(np.angle(frame[..., b] * np.conj(frame[..., a])))
    phase = np.where(strength_db(frame, config) >= min_db, phase, np.nan)
    im = ax.imshow(
        phase,
        origin="lower",
        aspect="auto",
        extent=image_extent(config),
        cmap="twilight",
        vmin=-180,
        vmax=180,
    )
    ax.set_xlabel("radial velocity [m/s]")
    ax.set_ylabel("range [m]")
    plt.colorbar(im, ax=ax, label=f"phase rx{b} - rx{a} [deg]")
    return im


def save_frame_figure(
    frame: np.ndarray,
    config: RadarConfig,
    path: str | Path,
    title: str = "",
    markers: Sequence[tuple[float, float, str]] = (),
    hlines: Sequence[tuple[float, str]] = (),
    vlines: Sequence[tuple[float, str]] = (),
) -> Path:
    """Strength and phase-difference panels side by side, with optional markers and guide lines.

    ``markers`` are (velocity_mps, range_m, label); ``hlines`` (range_m, label) and ``vlines``
    (velocity_mps, label) draw closed-form asymptotes for comparison.

    Parameters
    ----------
    frame : ndarray
        One frame, (range, doppler, rx), complex.
    config : RadarConfig
        The radar (axes and noise power).
    path : str or Path
        The image to write (format by its suffix), atomically.
    title : str
        Prefix of both panels' titles.
    markers : sequence of (float, float, str)
        Circles at (radial velocity m/s, range m), with their legend labels.
    hlines : sequence of (float, str)
        Horizontal lines at a range, m, with their labels.
    vlines : sequence of (float, str)
        Vertical lines at a radial velocity, m/s, with their labels.

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    A 13 x 5.2 in figure at 110 dpi is 1430 x 572 pixels:

    >>> import tempfile
    >>> cfg = RadarConfig.prototype_2022()
    >>> frame = np.full((cfg.n_range, cfg.n_doppler, cfg.n_rx), np.sqrt(100 * cfg.noise_power_w), complex)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = save_frame_figure(frame, cfg, Path(d) / "frame.png", "test", markers=[(0.0, 600.0, "target")])
    ...     shape = plt.imread(p).shape
    >>> p.name, shape
    ('frame.png', (572, 1430, 4))
    """
    path = Path(path)
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2), constrained_layout=True)
    plot_strength(frame, config, axes[0])
    plot_phase_difference(frame, config, (0, 1), axes[1])
    for ax in axes:
        for r_m, label in hlines:
            ax.axhline(r_m, color="w", lw=0.8, ls="--", label=label)
        for v, label in vlines:
            ax.axvline(v, color="orange", lw=0.8, ls="--", label=label)
        for v, r_m, label in markers:
            ax.plot(v, r_m, "o", mfc="none", mec="r", ms=12, mew=1.5, label=label)
        if hlines or vlines or markers:
            ax.legend(loc="upper left", fontsize=8, framealpha=0.6)
    axes[0].set_title(f"{title} strength")
    axes[1].set_title(f"{title} phase difference")
    try:
        return savefig_atomic(fig, path, dpi=110)
    finally:
        plt.close(fig)
