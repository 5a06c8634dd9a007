"""The ``navigation:`` section of a scenario: how wrong the own-ship's GNSS and AHRS are (plain data).

A real aircraft knows its position and velocity from a GNSS receiver and its attitude from an
AHRS, both with errors, and a little late. The simulator writes that navigation solution as the
frames' ``nav_*`` variables (:mod:`skyradar.sim.navigation`) beside the ``own_*`` truth, and
process, track and alert read only ``nav_*``. The model lives in the scene layer so a scenario
names it without importing the simulator.

Each error is a white noise per sample plus a first-order Gauss-Markov bias (stationary standard
deviation ``*_bias_*``, correlation time ``*_tau_s``), the usual model of both GNSS position error
and MEMS AHRS drift. Named models:

``ga-typical`` (the default), one axis 1-sigma:

- GNSS position, an SBAS receiver of TSO-C145/C146 class: horizontal bias 1.5 m per axis
  (tau 300 s) plus 0.3 m noise, vertical bias 2.5 m plus 0.5 m noise. The FAA WAAS Performance
  Analysis Reports give about 1 m horizontal and 1.5 m vertical at 95 %; the 14 CFR 91.227
  ADS-B Out rule accepts 0.05 NM (NACp 8). The values here are an assumption between the two,
  on the cautious side of what SBAS delivers.
- GNSS velocity (carrier Doppler): 0.1 m/s horizontal and 0.2 m/s vertical noise, 0.05 m/s
  bias (tau 60 s), from typical receiver datasheets (0.05-0.1 m/s); an assumption.
- AHRS, a MEMS unit of the class in GA glass cockpits (VectorNav VN-100 datasheet class:
  pitch/roll 0.5 deg static, 1 deg dynamic, magnetic heading 2 deg RMS): pitch and roll 0.1 deg
  noise plus 0.3 deg bias (tau 100 s), heading 0.2 deg noise plus 1.5 deg bias (tau 300 s), as
  :mod:`skyradar.sim.navigation`'s AhrsModel used for ch5.
- Latency (uncompensated age of the data when a radar frame uses it): GNSS 0.2 s, AHRS 0.02 s.
  14 CFR 91.227 allows 0.6 s of uncompensated GNSS latency; 0.2 s is an assumption.

``perfect`` has no error at all (the navigation equals the truth). ``only-gnss-position``,
``only-gnss-velocity``, ``only-attitude`` (pitch and roll), ``only-heading`` and ``only-latency``
keep one group of ``ga-typical``'s errors and zero the others, so the cost of each error can be
shown. Any field may be overridden: ``{model: ga-typical, heading_bias_deg: 3}``.

Examples
--------
>>> navigation_config("perfect").heading_bias_deg
0.0
>>> cfg = navigation_config({"model": "only-heading", "heading_bias_deg": 3})
>>> cfg.heading_bias_deg, cfg.gnss_horizontal_bias_m, cfg.model
(3.0, 0.0, 'only-heading')
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from skyradar.errors import InputError

__all__ = ["NAVIGATION_MODELS", "NAVIGATION_GROUPS", "NavigationConfig", "navigation_config", "with_preset"]

_GA_TYPICAL: dict[str, float] = {
    "gnss_horizontal_bias_m": 1.5,
    "gnss_horizontal_noise_m": 0.3,
    "gnss_vertical_bias_m": 2.5,
    "gnss_vertical_noise_m": 0.5,
    "gnss_position_tau_s": 300.0,
    "gnss_velocity_noise_mps": 0.1,
    "gnss_vertical_velocity_noise_mps": 0.2,
    "gnss_velocity_bias_mps": 0.05,
    "gnss_velocity_tau_s": 60.0,
    "roll_pitch_noise_deg": 0.1,
    "roll_pitch_bias_deg": 0.3,
    "roll_pitch_tau_s": 100.0,
    "heading_noise_deg": 0.2,
    "heading_bias_deg": 1.5,
    "heading_tau_s": 300.0,
    "gnss_latency_s": 0.2,
    "ahrs_latency_s": 0.02,
}
# The error groups of the single-error ablations (correlation times are not errors: always kept).
NAVIGATION_GROUPS: dict[str, tuple[str, ...]] = {
    "gnss-position": (
        "gnss_horizontal_bias_m",
        "gnss_horizontal_noise_m",
        "gnss_vertical_bias_m",
        "gnss_vertical_noise_m",
    ),
    "gnss-velocity": (
        "gnss_velocity_noise_mps",
        "gnss_vertical_velocity_noise_mps",
        "gnss_velocity_bias_mps",
    ),
    "attitude": ("roll_pitch_noise_deg", "roll_pitch_bias_deg"),
    "heading": ("heading_noise_deg", "heading_bias_deg"),
    "latency": ("gnss_latency_s", "ahrs_latency_s"),
}
NAVIGATION_MODELS = ("perfect", "ga-typical", *(f"only-{g}" for g in NAVIGATION_GROUPS))
_TAUS = ("gnss_position_tau_s", "gnss_velocity_tau_s", "roll_pitch_tau_s", "heading_tau_s")


ModelName = Literal[
    "perfect",
    "ga-typical",
    "only-gnss-position",
    "only-gnss-velocity",
    "only-attitude",
    "only-heading",
    "only-latency",
]


def _preset(model: str) -> dict[str, float]:
    if model == "ga-typical":
        return dict(_GA_TYPICAL)
    keep = NAVIGATION_GROUPS.get(model.removeprefix("only-"), ()) if model.startswith("only-") else ()
    return {k: (v if k in keep or k in _TAUS else 0.0) for k, v in _GA_TYPICAL.items()}


def with_preset(value: Any) -> Any:
    """The section as a dict with its named model's values filled in (a pydantic BeforeValidator).

    ``None`` is ``ga-typical``; a name is ``{model: name}``; anything that is not a known model
    passes through unchanged for the model's own validation to refuse.

    Parameters
    ----------
    value : None, str or dict
        The scenario's ``navigation`` section as written.

    Returns
    -------
    dict or Any
        Every field of the named model, the keys given in ``value`` replacing its values; ``value``
        itself when it names no known model.

    Examples
    --------
    >>> heading = with_preset("only-heading")
    >>> heading["model"], heading["heading_bias_deg"], heading["gnss_latency_s"], heading["heading_tau_s"]
    ('only-heading', 1.5, 0.0, 300.0)
    >>> with_preset({"model": "perfect", "gnss_latency_s": 0.1})["gnss_latency_s"]
    0.1
    >>> with_preset({"model": "unknown"})
    {'model': 'unknown'}
    """
    if value is None or isinstance(value, str):
        value = {"model": "ga-typical" if value is None else value}
    if not isinstance(value, dict) or value.get("model", "ga-typical") not in NAVIGATION_MODELS:
        return value
    name = value.get("model", "ga-typical")
    return _preset(name) | {"model": name} | dict(value)


def _up_to(high: float, description: str) -> Any:
    return Field(ge=0.0, le=high, allow_inf_nan=False, description=description)


def _tau(description: str) -> Any:
    # Correlation times up to about 12 days, s.
    return Field(gt=0.0, le=1e6, allow_inf_nan=False, description=description)


class NavigationConfig(BaseModel):
    """One navigation error model: how wrong and how late the own-ship's GNSS and AHRS are.

    Each error is a white noise per sample plus a first-order Gauss-Markov bias (its stationary
    standard deviation ``*_bias_*`` and correlation time ``*_tau_s``). A plain string is a model
    name (``navigation: only-heading``); keys given beside ``model`` override its values. The
    values of ``ga-typical`` and their sources: :mod:`skyradar.scene.navigation_config`.

    Examples
    --------
    Validated from a section with its model's values filled in (:func:`with_preset`):

    >>> latency = NavigationConfig.model_validate(with_preset("only-latency"))
    >>> latency.gnss_latency_s, latency.ahrs_latency_s, latency.heading_bias_deg, latency.is_perfect
    (0.2, 0.02, 0.0, False)
    >>> NavigationConfig.model_validate(with_preset("perfect")).is_perfect
    True
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)
    model: ModelName = Field(
        "ga-typical",
        description="The named error model whose values the fields not given here take (``perfect``, "
        "``ga-typical``, or ``only-GROUP``: one group of ``ga-typical``'s errors, the others zero).",
    )
    seed: int | None = Field(
        None, ge=0, description="Seed of the error draws; unset: the scenario's ``simulation.seed``."
    )
    # Plausible ranges: the errors of working avionics. Beyond them the model describes a failed
    # sensor (a GNSS bias of kilometres, a heading off by tens of degrees), which is a different study
    # (skyradar gpscheck's spoofing options), and a slip of units (mm for m) would silently blind the chain.
    gnss_horizontal_bias_m: float = _up_to(100.0, "GNSS horizontal position bias per axis, 1-sigma, m.")
    gnss_horizontal_noise_m: float = _up_to(50.0, "GNSS horizontal position noise per axis, 1-sigma, m.")
    gnss_vertical_bias_m: float = _up_to(150.0, "GNSS vertical position bias, 1-sigma, m.")
    gnss_vertical_noise_m: float = _up_to(50.0, "GNSS vertical position noise, 1-sigma, m.")
    gnss_position_tau_s: float = _tau("Correlation time of the GNSS position biases, s.")
    gnss_velocity_noise_mps: float = _up_to(5.0, "GNSS horizontal velocity noise per axis, 1-sigma, m/s.")
    gnss_vertical_velocity_noise_mps: float = _up_to(5.0, "GNSS vertical velocity noise, 1-sigma, m/s.")
    gnss_velocity_bias_mps: float = _up_to(5.0, "GNSS velocity bias per axis, 1-sigma, m/s.")
    gnss_velocity_tau_s: float = _tau("Correlation time of the GNSS velocity bias, s.")
    roll_pitch_noise_deg: float = _up_to(10.0, "AHRS roll and pitch noise, 1-sigma, degrees.")
    roll_pitch_bias_deg: float = _up_to(10.0, "AHRS roll and pitch bias, 1-sigma, degrees.")
    roll_pitch_tau_s: float = _tau("Correlation time of the roll and pitch biases, s.")
    heading_noise_deg: float = _up_to(20.0, "AHRS heading noise, 1-sigma, degrees.")
    heading_bias_deg: float = _up_to(30.0, "AHRS heading bias, 1-sigma, degrees.")
    heading_tau_s: float = _tau("Correlation time of the heading bias, s.")
    gnss_latency_s: float = Field(
        ge=0.0,
        le=5.0,
        allow_inf_nan=False,
        description="Age of the GNSS data when a radar frame uses it (uncompensated latency), s.",
    )
    ahrs_latency_s: float = Field(
        ge=0.0, le=5.0, allow_inf_nan=False, description="Age of the AHRS data when a radar frame uses it, s."
    )

    @property
    def is_perfect(self) -> bool:
        """No error of any kind: the navigation equals the truth."""
        return all(getattr(self, k) == 0.0 for k in _GA_TYPICAL if k not in _TAUS)


def navigation_config(value: Any = None, label: str = "navigation") -> NavigationConfig:
    """A :class:`NavigationConfig` from a model name, a ``{model: ..., overrides}`` dict or None.

    Raises :class:`InputError` naming ``label``, the field and the value on anything else.

    Examples
    --------
    >>> navigation_config().model, navigation_config(None).gnss_latency_s
    ('ga-typical', 0.2)
    """
    if isinstance(value, NavigationConfig):
        return value
    value = with_preset(value)
    if not isinstance(value, dict):
        raise InputError(f"{label}: must be a model name or a mapping, got {value!r}")
    if value.get("model") not in NAVIGATION_MODELS:
        names = ", ".join(NAVIGATION_MODELS)
        raise InputError(f"{label}: field 'model' must be one of {names}, got {value.get('model')!r}")
    try:
        return NavigationConfig.model_validate(value)
    except ValidationError as exc:
        err = exc.errors()[0]
        field = ".".join(str(p) for p in err["loc"]) or "model"
        raise InputError(f"{label}: field '{field}' {err['msg'].lower()}, got {err.get('input')!r}") from None
