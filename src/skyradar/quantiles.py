"""Quantiles of the chi-square, normal and gamma laws through :mod:`scipy.special`.

Gates and tests take a quantile of a known law (a chi-square gate on a normalised innovation, a
normal tail, the gamma law of a sum of exponential powers). :mod:`scipy.stats` gives them, but
importing it costs about half a second, which every command that gates pays before it reads its
first row. The same numbers follow from the regularised incomplete gamma function and the inverse
normal CDF, which :mod:`scipy.special` holds:

- chi-square with ``k`` degrees of freedom is gamma with shape ``k / 2`` and scale 2, so its
  quantile at ``q`` is ``2 * gammaincinv(k / 2, q)`` and its upper tail quantile at ``p`` is
  ``2 * gammainccinv(k / 2, p)``;
- the standard normal's upper tail quantile at ``p`` is ``-ndtri(p)``;
- gamma with shape ``a`` and unit scale has quantile ``gammaincinv(a, q)`` and upper tail quantile
  ``gammainccinv(a, p)``.
"""

from __future__ import annotations

from scipy.special import gammainccinv, gammaincinv, ndtri

__all__ = [
    "chi2_quantile",
    "chi2_upper_quantile",
    "normal_upper_quantile",
    "gamma_quantile",
    "gamma_upper_quantile",
]


def chi2_quantile(probability: float, dof: float) -> float:
    """The value a chi-square variable with ``dof`` degrees of freedom stays below with ``probability``.

    Parameters
    ----------
    probability : float
        In (0, 1).
    dof : float
        Degrees of freedom, > 0.

    Returns
    -------
    float
        ``scipy.stats.chi2.ppf(probability, dof)``.

    Examples
    --------
    >>> round(chi2_quantile(0.99, 3), 4)  # a 3-D gate that keeps 99 % of true innovations
    11.3449
    """
    return float(2.0 * gammaincinv(0.5 * dof, probability))


def chi2_upper_quantile(tail: float, dof: float) -> float:
    """The value a chi-square variable with ``dof`` degrees of freedom exceeds with probability ``tail``.

    Parameters
    ----------
    tail : float
        In (0, 1); the false-rejection rate of a test that rejects above the returned value.
    dof : float
        Degrees of freedom, > 0.

    Returns
    -------
    float
        ``scipy.stats.chi2.isf(tail, dof)``; accurate for tails far smaller than ``1 - 0.99``.

    Examples
    --------
    >>> round(chi2_upper_quantile(1e-3, 2), 4)  # -2 ln(1e-3)
    13.8155
    """
    return float(2.0 * gammainccinv(0.5 * dof, tail))


def normal_upper_quantile(tail: float) -> float:
    """The value a standard normal variable exceeds with probability ``tail``.

    Parameters
    ----------
    tail : float
        In (0, 1).

    Returns
    -------
    float
        ``scipy.stats.norm.isf(tail)``.

    Examples
    --------
    >>> round(normal_upper_quantile(0.025), 4)
    1.96
    """
    return float(-ndtri(tail))


def gamma_quantile(probability: float, shape: float) -> float:
    """The value a unit-scale gamma variable of ``shape`` stays below with ``probability``.

    Parameters
    ----------
    probability : float
        In (0, 1).
    shape : float
        Shape parameter, > 0 (the number of unit-mean exponential powers summed).

    Returns
    -------
    float
        ``scipy.stats.gamma.ppf(probability, shape)``.

    Examples
    --------
    >>> round(gamma_quantile(0.5, 1), 4)  # median of a unit exponential: ln 2
    0.6931
    """
    return float(gammaincinv(shape, probability))


def gamma_upper_quantile(tail: float, shape: float) -> float:
    """The value a unit-scale gamma variable of ``shape`` exceeds with probability ``tail``.

    Parameters
    ----------
    tail : float
        In (0, 1).
    shape : float
        Shape parameter, > 0.

    Returns
    -------
    float
        ``scipy.stats.gamma.isf(tail, shape)``.

    Examples
    --------
    >>> round(gamma_upper_quantile(1e-5, 1), 4)  # a unit exponential exceeds -ln(1e-5) once in 1e5
    11.5129
    """
    return float(gammainccinv(shape, tail))
