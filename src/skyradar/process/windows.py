"""FFT windows by name, and their coherent and noise power gains for a radar's frame.

Names a user types (``hann``, ``hamming``, ``blackmanharris``, ``chebyshev[:SIDELOBE_DB]``,
``none``) map to :func:`scipy.signal.get_window`; the gains tell how an on-bin target's pixel
power and the noise per pixel change with the windows (see :mod:`skyradar.process.rangedoppler`).
"""

from __future__ import annotations

import numpy as np

from skyradar.config import RadarConfig
from skyradar.errors import InputError

__all__ = ["WINDOWS", "WindowSpec", "get_window", "window_gain_db", "window_noise_gain_db"]

# fmt: off
# User-facing window names -> scipy.signal.get_window names.
WINDOWS: dict[str, str] = {
    "hann": "hann", "hanning": "hann", "hamming": "hamming", "blackmanharris": "blackmanharris",
    "blackman-harris": "blackmanharris", "chebyshev": "chebwin", "chebwin": "chebwin",
    "none": "boxcar", "rect": "boxcar", "boxcar": "boxcar",
}
# fmt: on
DEFAULT_CHEBYSHEV_SIDELOBE_DB = 80.0

WindowSpec = str | tuple[str, float] | None


def _window_key(spec: WindowSpec) -> tuple[str, float | None]:
    """Normalise ``'hann'``, ``'chebyshev:90'``, ``('chebyshev', 90)`` or None to (scipy name, param)."""
    if spec is None:
        return ("boxcar", None)
    param: float | None = None
    if isinstance(spec, tuple | list):
        if len(spec) != 2:
            raise InputError(f"window: expected (name, sidelobe_db), got {spec!r}")
        name, param = str(spec[0]), float(spec[1])
    else:
        name, _, rest = str(spec).partition(":")
        if rest:
            try:
                param = float(rest)
            except ValueError:
                raise InputError(f"window: parameter of {spec!r} is not a number") from None
    key = WINDOWS.get(name.strip().lower())
    if key is None:
        raise InputError(f"window: unknown window {name!r}; choose from {sorted(set(WINDOWS))}")
    if key == "chebwin":
        param = DEFAULT_CHEBYSHEV_SIDELOBE_DB if param is None else param
        if not (np.isfinite(param) and param > 0):
            raise InputError(f"window: chebyshev sidelobe level must be a positive dB value, got {param!r}")
    elif param is not None:
        raise InputError(f"window: {name!r} takes no parameter (got {param!r})")
    return (key, param)


def get_window(spec: WindowSpec, n: int) -> np.ndarray:
    """Periodic (DFT-even) window of length ``n`` from :func:`scipy.signal.get_window`.

    Parameters
    ----------
    spec : str, (str, float) or None
        ``'hann'``, ``'hamming'``, ``'blackmanharris'``, ``'chebyshev'`` (sidelobes at -80 dB),
        ``'chebyshev:100'`` or ``('chebyshev', 100)`` (sidelobe level in dB), ``'none'``/None.
    n : int
        Length.

    Examples
    --------
    >>> round(float(get_window('hann', 8).mean()), 3)
    0.5
    """
    # Imported here: scipy.signal takes about half a second to import, which a command that stops
    # on its input (or never makes a window) should not pay.
    import scipy.signal

    name, param = _window_key(spec)
    return scipy.signal.get_window(name if param is None else (name, param), int(n), fftbins=True)


def _gain_db(range_window: WindowSpec, doppler_window: WindowSpec, config: RadarConfig, power: int) -> float:
    wr = get_window(range_window, config.samples_per_chirp)
    wd = get_window(doppler_window, config.n_doppler)
    if power == 1:
        return float(20.0 * np.log10(wr.mean() * wd.mean()))
    return float(10.0 * np.log10(np.mean(wr**2) * np.mean(wd**2)))


def window_gain_db(
    range_window: WindowSpec = "hann", doppler_window: WindowSpec = "hann", config: RadarConfig | None = None
) -> float:
    """Coherent power gain of the two windows for an on-bin target, dB (<= 0).

    Add ``-window_gain_db(...)`` to a pixel's power in dB to get the received power.

    Examples
    --------
    >>> round(window_gain_db('hann', 'hann'), 2)
    -12.04
    """
    return _gain_db(range_window, doppler_window, config or RadarConfig.prototype_2022(), 1)


def window_noise_gain_db(
    range_window: WindowSpec = "hann", doppler_window: WindowSpec = "hann", config: RadarConfig | None = None
) -> float:
    """Power gain of the two windows for white noise, dB (mean of w^2 per axis).

    Examples
    --------
    >>> round(window_noise_gain_db('hann', 'hann'), 2)
    -8.52
    """
    return _gain_db(range_window, doppler_window, config or RadarConfig.prototype_2022(), 2)
