"""Towing decisions over ensembles (docs/towing.md): the odds that a tow succeeds by criteria a
planner names, with Wilson intervals; the seeds a point needs for an interval of a given width;
design loads from a generalised extreme value (GEV) fit of per-tow maxima, with bootstrap
intervals and a quantile plot.

    outcomes = [floedem.open(p).tow.outcome for p in paths]      # one per field seed
    ok = [floedem.towing.succeeded(o, min_speed=0.3) for o in outcomes]
    floedem.towing.odds(ok)                   # {"p", "lo", "hi", "n", "successes"}
    fit = floedem.towing.gev_fit([o["tension_max"] for o in outcomes])
    floedem.towing.design_loads([o["tension_max"] for o in outcomes], periods=(10, 100))

Each tow is taken as independent of the others (one field seed each), and the GEV's tail comes
from a few dozen maxima: the return level of a period much longer than the ensemble is an
extrapolation, and its bootstrap interval says how far."""
import math

import numpy as np


def _z(confidence):
    from scipy.stats import norm
    return float(norm.ppf(0.5 + 0.5 * confidence))


def wilson_interval(successes, n, confidence=0.95):
    """The Wilson score interval of a binomial proportion (Wilson 1927; Agresti and Coull 1998):
    the p whose normal test does not reject `successes` of `n`, centre (k + z^2/2) / (n + z^2),
    half-width z sqrt(k (n - k) / n + z^2 / 4) / (n + z^2). Unlike the Wald interval it stays in
    [0, 1] and keeps its coverage near 0 and 1, where a planner's odds live. Returns (lo, hi)."""
    if n <= 0:
        raise ValueError("wilson_interval: n must be at least 1")
    if not 0 <= successes <= n:
        raise ValueError(f"wilson_interval: successes {successes} must lie in [0, {n}]")
    z = _z(confidence)
    k = float(successes)
    centre = (k + z * z / 2.0) / (n + z * z)
    half = z * math.sqrt(k * (n - k) / n + z * z / 4.0) / (n + z * z)
    return max(0.0, centre - half), min(1.0, centre + half)


def seeds_for_half_width(half_width, p=0.5, confidence=0.95):
    """The fewest runs whose Wilson interval about a proportion p is at most +-half_width: p = 0.5,
    the widest, unless the point's odds are known to lie elsewhere."""
    if not 0.0 < half_width < 0.5:
        raise ValueError("seeds_for_half_width: half_width must lie in (0, 0.5)")
    n = 1
    while True:
        lo, hi = wilson_interval(round(p * n), n, confidence)
        if (hi - lo) / 2.0 <= half_width:
            return n
        n += 1


def succeeded(outcome, no_parting=True, min_speed=None, min_distance=None, max_stalled=None):
    """Whether one tow met the planner's criteria: the rope held (no_parting), the speed made good
    (m/s) and the distance along the tow's direction (m) at least the given ones, and the time
    stalled (s) at most max_stalled. `outcome`: floedem.open(path).tow.outcome."""
    if outcome is None:
        raise ValueError("succeeded: the run has no tow outcome (not finished, or not a tow)")
    if no_parting and outcome["parted"]:
        return False
    if min_speed is not None and not outcome["speed_made_good"] >= min_speed:
        return False
    if min_distance is not None and not outcome["distance"] >= min_distance:
        return False
    if max_stalled is not None and not outcome["stalled_time"] <= max_stalled:
        return False
    return True


def odds(successes, confidence=0.95):
    """The probability of success over an ensemble of booleans, with its Wilson interval."""
    ok = [bool(x) for x in successes]
    n, k = len(ok), sum(ok)
    lo, hi = wilson_interval(k, n, confidence)
    return {"p": k / n, "lo": lo, "hi": hi, "n": n, "successes": k}


def smallest_pull(points, probability, conservative=True):
    """The smallest bollard pull whose odds reach `probability`: `points` are (pull, odds dict)
    pairs of one ice condition; conservative takes the interval's lower end, else the estimate.
    None when no pull reaches it."""
    key = "lo" if conservative else "p"
    for pull, o in sorted(points, key=lambda x: x[0]):
        if o[key] >= probability:
            return pull
    return None


def _gev_nll(theta, z):
    """Minus the GEV log-likelihood of standardised maxima z (Coles 2001, eq. 3.7 and 3.9) at
    theta = (xi, mu, ln sigma); inf outside the support 1 + xi (z - mu) / sigma > 0."""
    xi, mu, sigma = theta[0], theta[1], math.exp(theta[2])
    y = (z - mu) / sigma
    if abs(xi) < 1e-6:
        return z.size * theta[2] + np.sum(y) + np.sum(np.exp(-y))
    t = 1.0 + xi * y
    if np.any(t <= 0.0):
        return 1e300  # outside the support (finite: the simplex compares values by subtraction)
    return z.size * theta[2] + (1.0 + 1.0 / xi) * np.sum(np.log(t)) + np.sum(t ** (-1.0 / xi))


def gev_fit(maxima, start=None):
    """Maximum-likelihood GEV fit of per-tow maxima (Coles 2001, ch. 3): returns
    {"shape": xi, "loc": mu, "scale": sigma}, with xi > 0 a heavy (Frechet) tail, xi < 0 a bounded
    one. Fitted in standard units from the Gumbel's moment estimates (sigma = sqrt(6) s / pi,
    mu = mean - 0.5772 sigma) by Nelder-Mead: scipy's own genextreme.fit, tried first, stalls
    at its starting location on such data (a shape of 0.00 for a sample of xi = 0.1). `start`: a
    fit to begin from instead (the bootstrap's refits start from the sample's own fit)."""
    from scipy.optimize import minimize
    x = np.asarray(maxima, float)
    if x.size < 5 or not np.all(np.isfinite(x)):
        raise ValueError("gev_fit: needs at least 5 finite maxima")
    if np.ptp(x) == 0.0:
        raise ValueError("gev_fit: the maxima are all equal; no spread to fit")
    m, s = float(np.mean(x)), float(np.std(x))
    z = (x - m) / s
    sigma0 = math.sqrt(6.0) / math.pi
    starts = [[xi0, -0.5772 * sigma0, math.log(sigma0)] for xi0 in (-0.2, 0.0, 0.2)]
    if start is not None:
        starts = [[start["shape"], (start["loc"] - m) / s, math.log(start["scale"] / s)]]
    best = None
    for x0 in starts:
        r = minimize(_gev_nll, x0, args=(z,), method="Nelder-Mead",
                     options={"xatol": 1e-9, "fatol": 1e-12, "maxiter": 20000, "maxfev": 40000})
        if best is None or r.fun < best.fun:
            best = r
    xi, mu, log_sigma = best.x
    return {"shape": float(xi), "loc": m + s * float(mu), "scale": s * math.exp(float(log_sigma))}


def return_level(fit, period):
    """The load exceeded once in `period` tows on average: the GEV's 1 - 1/period quantile,
    mu + sigma ((-ln(1 - 1/T))^(-xi) - 1) / xi (mu - sigma ln(-ln(1 - 1/T)) at xi = 0)."""
    if not period > 1.0:
        raise ValueError("return_level: the period must exceed 1 tow")
    y = -math.log(1.0 - 1.0 / period)
    xi, mu, sigma = fit["shape"], fit["loc"], fit["scale"]
    if abs(xi) < 1e-9:
        return mu - sigma * math.log(y)
    return mu + sigma * (y ** (-xi) - 1.0) / xi


def design_loads(maxima, periods=(10, 100), boot=400, confidence=0.95, seed=0):
    """Return levels of the per-tow maxima for each period, each with a percentile bootstrap
    interval (the maxima resampled with replacement and refitted `boot` times; Davison and
    Hinkley 1997): [{"period", "level", "lo", "hi"}], and the fit."""
    x = np.asarray(maxima, float)
    fit = gev_fit(x)
    rng = np.random.default_rng(seed)
    levels = {T: [] for T in periods}
    for _ in range(boot):
        sample = rng.choice(x, size=x.size, replace=True)
        if np.ptp(sample) == 0.0:
            continue
        f = gev_fit(sample, start=fit)
        for T in periods:
            levels[T].append(return_level(f, T))
    a = (1.0 - confidence) / 2.0
    rows = []
    for T in periods:
        v = np.asarray(levels[T])
        v = v[np.isfinite(v)]
        rows.append({"period": T, "level": return_level(fit, T),
                     "lo": float(np.quantile(v, a)) if v.size else float("nan"),
                     "hi": float(np.quantile(v, 1.0 - a)) if v.size else float("nan")})
    return rows, fit


def quantile_plot(maxima, fit, ax):
    """The fit's quantile plot on a matplotlib axis: the sorted maxima against the GEV's quantiles
    at the plotting positions i / (n + 1) (Coles 2001, 3.3.3); points on the diagonal, a fit that
    holds."""
    from scipy.stats import genextreme
    x = np.sort(np.asarray(maxima, float))
    q = genextreme.ppf(np.arange(1, x.size + 1) / (x.size + 1.0), -fit["shape"], fit["loc"], fit["scale"])
    ax.plot(q, x, "o", ms=4)
    lo, hi = min(q.min(), x.min()), max(q.max(), x.max())
    ax.plot([lo, hi], [lo, hi], "k-", lw=0.8)
    ax.set_xlabel("GEV quantile")
    ax.set_ylabel("largest per tow")
    return ax


def table(rows, columns):
    """Rows (dicts) as a Markdown table a planner can paste, numbers to 4 significant figures."""
    def text(v):
        if isinstance(v, float):
            return f"{v:.4g}"
        return str(v)
    out = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    out += ["| " + " | ".join(text(r.get(c, "")) for c in columns) + " |" for r in rows]
    return "\n".join(out) + "\n"
