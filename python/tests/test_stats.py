"""floedem.stats against cases with known answers."""
import numpy as np
import pytest

from floedem import stats


def ar1(rng, n, phi):
    """x[i] = phi x[i - 1] + e[i], e standard normal: rho(k) = phi^k."""
    e = rng.standard_normal(n)
    x = np.empty(n)
    x[0] = e[0]
    for i in range(1, n):
        x[i] = phi * x[i - 1] + e[i]
    return x


def test_block_standard_error_of_independent_samples():
    # iid N(0, 1), 1 s apart, 30 s blocks: the error of the mean is 1 / sqrt(N); the block
    # estimate itself scatters by 1 / sqrt(2 (blocks - 1)) = 3 % with 600 blocks.
    rng = np.random.default_rng(7)
    n = 18000
    x = rng.standard_normal(n)
    t = np.arange(n, dtype=float)
    assert stats.block_standard_error(t, x, 30.0) == pytest.approx(1.0 / np.sqrt(n), rel=0.12)


def test_block_standard_error_sees_correlation():
    # AR(1) with phi = 0.9: the variance of the mean is (1 + phi) / (1 - phi) = 19 times that of
    # independent samples; blocks of 200 samples (21 integrated correlation times of 9.5) catch it
    # within 15 %.
    rng = np.random.default_rng(3)
    n, phi = 200000, 0.9
    x = ar1(rng, n, phi)
    sigma = 1.0 / np.sqrt(1.0 - phi * phi)
    expect = sigma * np.sqrt((1.0 + phi) / (1.0 - phi) / n)
    assert stats.block_standard_error(np.arange(n, dtype=float), x, 200.0) == pytest.approx(expect, rel=0.15)


def test_autocorrelation_time_of_ar1():
    # AR(1) with phi: rho(k) = phi^k, tau_int = 1/2 + phi / (1 - phi) = 9.5 samples for phi = 0.9;
    # the windowed estimate over 200 000 samples is within a few per cent.
    rng = np.random.default_rng(5)
    n, phi = 200000, 0.9
    x = ar1(rng, n, phi)
    assert stats.integrated_autocorrelation_time(x, 1.0) == pytest.approx(9.5, rel=0.05)
    assert stats.integrated_autocorrelation_time(rng.standard_normal(n), 2.0) == pytest.approx(1.0, rel=0.05)
    assert stats.justified_block(np.arange(n, dtype=float), x) == pytest.approx(95.0, rel=0.05)


def test_stationary_window():
    travelled = np.array([0.0, 5.0, 10.0, 15.0, 20.0])
    assert list(stats.stationary_window(travelled, 10.0)) == [False, False, True, True, True]
    assert list(stats.stationary_window(travelled, 0.0)) == [False, True, True, True, True]  # row 0 never
    with pytest.raises(ValueError, match="never travelled 25"):
        stats.stationary_window(travelled, 25.0)


def test_power_law_exponent_recovered():
    # Draws from the truncated law by inverting S(d): the MLE's standard error at n = 20000 is
    # about alpha / sqrt(n) = 0.014; 0.05 is 3.5 of them.
    rng = np.random.default_rng(11)
    alpha, d_min, d_max = 2.0, 5.0, 60.0
    u = rng.random(20000)
    d = (d_min ** -alpha - u * (d_min ** -alpha - d_max ** -alpha)) ** (-1.0 / alpha)
    assert stats.power_law_alpha(d, d_min, d_max) == pytest.approx(alpha, abs=0.05)
    assert stats.truncated_power_law_survival(d_min, alpha, d_min, d_max) == pytest.approx(1.0)
    assert stats.truncated_power_law_survival(d_max, alpha, d_min, d_max) == pytest.approx(0.0)


def test_summary():
    s = stats.summary([1.0, 2.0, 3.0, 4.0])
    assert s["mean"] == 2.5 and s["peak"] == 4.0 and s["p50"] == 2.5
