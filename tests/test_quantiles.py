"""The scipy.special quantiles equal scipy.stats' over the probabilities and dimensions gates use."""

import numpy as np
import pytest
from scipy import stats

from skyradar.quantiles import (
    chi2_quantile,
    chi2_upper_quantile,
    gamma_quantile,
    gamma_upper_quantile,
    normal_upper_quantile,
)

TAILS = [1e-9, 1e-6, 1e-3, 0.01, 0.05, 0.5, 0.9]
DOFS = [1, 2, 3, 4, 7.5, 20, 200]


@pytest.mark.parametrize("dof", DOFS)
def test_chi2_quantiles_equal_scipy_stats(dof):
    for p in TAILS:
        assert chi2_upper_quantile(p, dof) == pytest.approx(stats.chi2.isf(p, dof), rel=1e-10)
        assert chi2_quantile(1 - p, dof) == pytest.approx(stats.chi2.ppf(1 - p, dof), rel=1e-9)
        assert chi2_quantile(p, dof) == pytest.approx(stats.chi2.ppf(p, dof), rel=1e-9)


def test_normal_and_gamma_quantiles_equal_scipy_stats():
    for p in TAILS:
        assert normal_upper_quantile(p) == pytest.approx(stats.norm.isf(p), rel=1e-12, abs=1e-15)
        for shape in [1, 2, 4, 6, 16]:
            assert gamma_quantile(p, shape) == pytest.approx(stats.gamma.ppf(p, shape), rel=1e-10)
            assert gamma_upper_quantile(p, shape) == pytest.approx(stats.gamma.isf(p, shape), rel=1e-10)


def test_a_command_that_gates_does_not_load_scipy_stats():
    # The tracker's ground tests and the navigation gate are the modules a gating command loads.
    import subprocess
    import sys

    modules = [
        "skyradar.track.track_table",
        "skyradar.nav.kalman_state",
        "skyradar.nav.ridge",
        "skyradar.process.spurs",
        "skyradar.track.detectable",
    ]
    code = f"import sys, {', '.join(modules)}; print('scipy.stats' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
    assert np.isfinite(chi2_upper_quantile(1e-12, 3))
