"""The statistics floedem's report uses, in one place: the stationary part of a towing run, the
standard error of a mean of correlated samples, summary figures, and the truncated power law of
floe sizes with its maximum-likelihood exponent."""
import math

import numpy as np


def stationary_window(travelled, s_stat):
    """Rows of a towing run's stationary part: from the first row at which the iceberg has
    travelled `s_stat` metres (the ice pushed ahead of it has built up) to the end; row 0, which
    has no step yet, is never in it. `travelled`: distance along the path at each row, m (e.g.
    the tow's tug_position x minus its first value). ValueError when it never gets that far."""
    moved = np.asarray(travelled, float) - travelled[0]
    start = int(np.argmax(moved >= s_stat))
    if moved[start] < s_stat:
        raise ValueError(f"the iceberg never travelled {s_stat} m (it went {moved.max():.4g} m)")
    keep = np.zeros(len(moved), bool)
    keep[max(start, 1):] = True
    return keep


def block_standard_error(t, x, block):
    """Standard error of the mean of x, from the means of consecutive blocks `block` seconds
    long: for samples correlated over a time shorter than a block, the block means are nearly
    independent, and their scatter over sqrt(blocks) estimates the error of the overall mean
    (the batch-means method; Flyvbjerg and Petersen 1989). NaN with fewer than two blocks."""
    t = np.asarray(t, float)
    x = np.asarray(x, float)
    dt = t[1] - t[0] if len(t) > 1 else 1.0
    per = max(1, int(round(block / dt)))
    n = len(x) // per
    if n < 2:
        return float("nan")
    means = x[: n * per].reshape(n, per).mean(axis=1)
    return float(means.std(ddof=1) / math.sqrt(n))


def integrated_autocorrelation_time(x, dt=1.0, c=5.0):
    """tau_int = dt (1/2 + sum_k rho(k)), the sum over lags k >= 1 cut at the first k >= c tau
    (Sokal's automatic window, Sokal 1997; Madras and Sokal 1988): the time over which x stays
    correlated. The variance of a mean of samples spanning T is about 2 tau_int var(x) / T."""
    x = np.asarray(x, float) - np.mean(x)
    n = len(x)
    if n < 4 or not np.any(x):
        return float(dt / 2.0)
    f = np.fft.rfft(x, 2 * n)
    acf = np.fft.irfft(f * np.conj(f))[:n]
    rho = acf / acf[0]
    tau = 0.5
    for k in range(1, n):
        tau += rho[k]
        if k >= c * tau:
            break
    return float(max(tau, 0.5) * dt)


def justified_block(t, x, factor=10.0):
    """A block length for block_standard_error() from x's own correlation: factor times its
    integrated autocorrelation time (blocks many correlation times long have nearly independent
    means), at least one sample."""
    t = np.asarray(t, float)
    dt = t[1] - t[0] if len(t) > 1 else 1.0
    return max(dt, factor * integrated_autocorrelation_time(x, dt))


def summary(x):
    """Mean, standard deviation, peak, and the 50th, 90th and 99th percentiles."""
    x = np.asarray(x, float)
    return dict(mean=float(np.mean(x)), std=float(np.std(x)), peak=float(np.max(x)),
                p50=float(np.percentile(x, 50)), p90=float(np.percentile(x, 90)), p99=float(np.percentile(x, 99)))


def equal_area_diameters(area):
    """d = sqrt(4 A / pi), m, of polygons of area A (m^2)."""
    return np.sqrt(4.0 * np.asarray(area, float) / np.pi)


def truncated_power_law_survival(d, alpha, d_min, d_max):
    """S(d) = (d^-alpha - d_max^-alpha) / (d_min^-alpha - d_max^-alpha): the fraction of floes
    larger than d under the field generator's size law (docs/model.md section 5)."""
    d = np.clip(np.asarray(d, float), d_min, d_max)
    return (d ** -alpha - d_max ** -alpha) / (d_min ** -alpha - d_max ** -alpha)


def power_law_alpha(d, d_min, d_max):
    """Maximum-likelihood exponent of a truncated power law (after Clauset, Shalizi and Newman
    2009), by golden-section search on [0.01, 10]: pdf p(d) = alpha d^(-alpha - 1) /
    (d_min^-alpha - d_max^-alpha) on [d_min, d_max]. An independent check of the generator's own
    fit (/field@alpha_fitted)."""
    d = np.asarray(d, float)
    logs = np.log(d).sum()
    n = len(d)

    def nll(a):
        return -(n * np.log(a) - (a + 1.0) * logs - n * np.log(d_min ** -a - d_max ** -a))

    lo, hi = 0.01, 10.0
    g = (np.sqrt(5.0) - 1.0) / 2.0
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    for _ in range(200):
        if nll(x1) < nll(x2):
            hi, x2 = x2, x1
            x1 = hi - g * (hi - lo)
        else:
            lo, x1 = x1, x2
            x2 = lo + g * (hi - lo)
    return 0.5 * (lo + hi)
