"""Named receive-array layouts: antenna phase centres in the antenna frame (y right, z down), m.

``square`` is the thesis prototype's coplanar 2x2 at half-wavelength spacing. It is centrally
symmetric, and that costs it the elevation of a target whose clutter is nulled at two azimuths of
one elevation (an aircraft above or below level flight over flat ground shares its Doppler with
ground on both sides): after the two nulls the array's Fisher information on (azimuth, elevation)
has rank 1, for any rotation of the square about its boresight.

``kite`` keeps four antennas and the upper half-wavelength pair but moves the lower two onto the
vertical axis, one and two half-wavelengths below the upper pair: a triangle with a tail and no
centre of symmetry, so the same two nulls leave the elevation measurable. It pays with its
azimuth there: mirror-symmetric about its vertical axis, its one horizontal baseline is the upper
pair, which the antisymmetric combination of the two nulls takes, so its azimuth's bound through
them is 6-22 deg where the square's is 0.7-2 deg at 27 dB
(:func:`skyradar.process.clutter_doa.angle_sigmas_rad`; the blind axis turns from horizontal to
vertical). Over hills it can warn a conflict 1.7-22 s later than the square: a track's azimuth
drifts up to 31 deg off over 23 s, and the track is dropped and started again.
Its vertical aperture of one wavelength is unambiguous through the two half-wavelength pairs
(:mod:`skyradar.process.doa` unwraps the long baseline from them).

``ura-2x3`` and ``ura-2x4`` are uniform rectangular arrays at the prototype's half-wavelength
element spacing: two rows (one above the other) of three or four columns across, centred on the
boresight axis. More channels buy angle accuracy (the Cramer-Rao bound falls with the aperture's
second moments, :func:`skyradar.process.doa.doa_crlb`) and room for more clutter nulls, which
cost the target too (:func:`skyradar.process.clutter_suppress.default_max_nulls`). ``ura-4x2`` stands
the same eight channels upright: four rows of two columns. Its vertical aperture (1.5 wavelengths)
gives an elevation bound 3.2 times smaller than the square's at the same per-channel SNR (the
rows' second moment is 5 times the square's, the channel count twice): 1.3 deg against 4.1 deg
at 10 dB per channel (:func:`~skyradar.process.doa.doa_crlb`). An aircraft 250 m above the
own-ship 3 km ahead is 4.8 deg up, a little over one of the square's sigmas from co-altitude.
Its azimuth keeps the square's half-wavelength horizontal baseline, its bound 1.4 times smaller
from the channel count. Over relief it confirms ground tracks many times as often as the square:
the return of the ground below the aircraft, which the square's ground tests recognise at the
end-fire of its vertical baseline, reaches four rows as no plane wave; the arrays guide says so
with the measured set.

Unambiguous field of view: every layout here has half-wavelength pairs spanning the array plane
(the kite's one-wavelength baseline is unwrapped from them), so each is free of grating lobes
over the whole forward half-space, azimuth and elevation -90..90 deg; the antenna pattern, not the
array, limits the usable field of view (:func:`skyradar.process.doa.array_geometry`).

Any other array is given by its positions (``radar.rx_positions_m``, 1 to :data:`MAX_RX` rows).

Time-division MIMO layouts name transmitters and receivers together (:func:`mimo_layout_m`);
the transmitters take turns chirp by chirp and every transmitter-receiver pair is a virtual
channel at ``tx + rx`` (:mod:`skyradar.config`). ``mimo-2x4`` is four receivers in a row across
at half-wavelength spacing and two transmitters on the vertical axis half a wavelength apart: its
virtual array is the uniform 2x4 at half-wavelength spacing (``ura-2x4``'s positions, in the same
row-major order), from six antennas instead of eight. With half-wavelength pairs spanning its
plane, the virtual array is free of grating lobes over the whole forward half-space, azimuth and
elevation -90..90 deg. Its transmitters' slots widen one ambiguity: a radial velocity aliased
beyond the per-transmitter limit shifts the second row's phase by pi, which mimics a direction
whose ``down`` direction cosine differs by 1. :func:`skyradar.process.mimo.virtual_pixels` tells
the two apart by the antenna's field of view (the cone within 6 dB of peak gain, half-angle
``alpha``): unique where the alias direction falls outside it, which holds everywhere for
``alpha < 30 deg`` and otherwise for ``|sin(el)| < 1 - sin(alpha)`` (within 13.9 deg of the
horizontal plane for the prototype's 49.5 deg); closer to the cone's top and bottom both
hypotheses fit and the velocity stays ambiguous by a factor of two.

Examples
--------
>>> rx_layout_m("square", 0.04).round(3).tolist()[0]
[0.0, -0.01, -0.01]
>>> rx_layout_m("kite", 0.04)[:, 2].round(3).tolist()  # down, m
[-0.01, -0.01, 0.01, 0.03]
"""

from __future__ import annotations

from typing import Literal, get_args

import numpy as np

from skyradar.errors import InputError

__all__ = [
    "ArrayLayout",
    "MAX_RX",
    "MAX_TX",
    "MIMO_LAYOUTS",
    "MimoLayout",
    "RX_LAYOUTS",
    "RxLayout",
    "check_rx_layout",
    "mimo_layout_m",
    "rx_layout_m",
    "square_m",
    "ura_m",
]

RxLayout = Literal["square", "kite", "ura-2x3", "ura-2x4", "ura-4x2"]  # the layouts' names
RX_LAYOUTS: tuple[str, ...] = get_args(RxLayout)
MAX_RX = 32  # receive channels a radar may have (CFAR and noise-floor tables are built up to it)
MimoLayout = Literal["mimo-2x4"]  # named transmitter + receiver layouts (time-division MIMO)
MIMO_LAYOUTS: tuple[str, ...] = get_args(MimoLayout)
ArrayLayout = Literal[RxLayout, MimoLayout]  # every named array: receive-only or MIMO
MAX_TX = 4  # transmitters of a time-division MIMO radar (each costs a factor in unambiguous Doppler)


def rx_layout_m(name: str, wavelength_m: float) -> np.ndarray:
    """Receive antenna positions (n_rx, 3), m, of a named layout for the wavelength ``wavelength_m`` (m).

    Parameters
    ----------
    name : str
        ``"square"`` (2x2, half-wavelength sides), ``"kite"``, ``"ura-2x3"``, ``"ura-2x4"`` or
        ``"ura-4x2"`` (rows x columns; see the module docstring).
    wavelength_m : float
        Carrier wavelength, m.

    Returns
    -------
    ndarray, shape (n_rx, 3)
        Rows (0, right, down) in the antenna frame, m (4 rows; 6 and 8 for the URAs), centred on the
        boresight axis for the square and the URAs.

    Examples
    --------
    >>> rx_layout_m("kite", 0.04)[:, 1].round(3).tolist()  # right, m
    [-0.01, 0.01, 0.0, 0.0]
    >>> rx_layout_m("ring", 0.04)
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: radar.rx_positions_m: layout must be one of square, kite, ..., got 'ring'
    """
    check_rx_layout(name, "radar.rx_positions_m: layout")
    if name == "square":
        return square_m(float(wavelength_m) / 2.0)
    if name.startswith("ura-"):
        rows, cols = (int(v) for v in name[4:].split("x"))
        return ura_m(rows, cols, float(wavelength_m) / 2.0)
    q = float(wavelength_m) / 4.0
    return np.array([[0.0, -q, -q], [0.0, q, -q], [0.0, 0.0, q], [0.0, 0.0, 3.0 * q]])


def square_m(side_m: float) -> np.ndarray:
    """Positions (4, 3), m, of a 2x2 square of side ``side_m`` (m) centred on the boresight axis.

    Examples
    --------
    >>> square_m(0.02)[:, 1:].round(3).tolist()  # (right, down), m
    [[-0.01, -0.01], [0.01, -0.01], [-0.01, 0.01], [0.01, 0.01]]
    """
    h = float(side_m) / 2.0
    return np.array([[0.0, -h, -h], [0.0, h, -h], [0.0, -h, h], [0.0, h, h]])


def ura_m(rows: int, cols: int, spacing_m: float) -> np.ndarray:
    """Positions (rows * cols, 3), m, of a uniform rectangular array centred on the boresight axis.

    Row-major: the top row (most negative down) first, each row from left to right.

    Examples
    --------
    >>> ura_m(2, 3, 0.02)[:, 1:].round(3).tolist()  # (right, down), m
    [[-0.02, -0.01], [0.0, -0.01], [0.02, -0.01], [-0.02, 0.01], [0.0, 0.01], [0.02, 0.01]]
    """
    s = float(spacing_m)
    down, right = np.meshgrid(
        (np.arange(rows) - (rows - 1) / 2.0) * s, (np.arange(cols) - (cols - 1) / 2.0) * s, indexing="ij"
    )
    return np.column_stack([np.zeros(rows * cols), right.ravel(), down.ravel()])


def check_rx_layout(name: str, label: str, mimo: bool = False) -> str:
    """``name`` if it is a layout of :data:`RX_LAYOUTS` (or, with ``mimo``, of :data:`MIMO_LAYOUTS`),
    else InputError ``"{label} must be ..."``.

    Examples
    --------
    >>> check_rx_layout("kite", "--rx-layout")
    'kite'
    >>> check_rx_layout("mimo-2x4", "--rx-layout", mimo=True)
    'mimo-2x4'
    """
    names = RX_LAYOUTS + MIMO_LAYOUTS if mimo else RX_LAYOUTS
    if name not in names:
        raise InputError(f"{label} must be one of {', '.join(names)}, got {name!r}")
    return name


def mimo_layout_m(name: str, wavelength_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Transmit and receive positions, m, of a named time-division MIMO layout.

    Parameters
    ----------
    name : str
        ``"mimo-2x4"`` (module docstring).
    wavelength_m : float
        Carrier wavelength, m.

    Returns
    -------
    tx_m : ndarray, shape (n_tx, 3)
        Transmit phase centres (0, right, down), m; the top one first.
    rx_m : ndarray, shape (n_rx, 3)
        Receive phase centres (0, right, down), m, from left to right.

    Examples
    --------
    >>> tx, rx = mimo_layout_m("mimo-2x4", 0.04)
    >>> tx[:, 2].round(3).tolist(), rx[:, 1].round(3).tolist()
    ([-0.01, 0.01], [-0.03, -0.01, 0.01, 0.03])
    """
    if name not in MIMO_LAYOUTS:
        raise InputError(
            f"radar.rx_positions_m: MIMO layout must be one of {', '.join(MIMO_LAYOUTS)}, got {name!r}"
        )
    half = float(wavelength_m) / 2.0
    rx = ura_m(1, 4, half)
    tx = ura_m(2, 1, half)
    return tx, rx
