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
import json
import math
import os

import numpy as np

from .launch import csv_text


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


#: The fewest maxima a GEV is fitted to: three parameters, and below ten maxima the shape is noise;
#: and the fewest distinct ones among them, told apart at DISTINCT_RESOLUTION of their mean: a
#: line's largest tension, set by the tug taking up the iceberg before the ice counts, differs
#: from seed to seed by parts in 10^5, a spread of round-off and not a tail to fit.
MIN_MAXIMA = 10
MIN_DISTINCT = 5
DISTINCT_RESOLUTION = 1e-4


def _distinct(x):
    """How many of the values differ by more than DISTINCT_RESOLUTION of their mean magnitude."""
    step = DISTINCT_RESOLUTION * float(np.mean(np.abs(x)))
    return np.unique(np.round(x / step)).size if step > 0.0 else np.unique(x).size


def _gev_nll(theta, z):
    """Minus the GEV log-likelihood of standardised maxima z (Coles 2001, eq. 3.7 and 3.9) at
    theta = (xi, mu, ln sigma); inf outside the support 1 + xi (z - mu) / sigma > 0."""
    xi, mu = theta[0], theta[1]
    if abs(xi) > 1.0 or not -30.0 < theta[2] < 30.0:
        # A load's tail: xi >= 1 has no mean, xi <= -1 an unbounded likelihood (Coles 2001,
        # 3.3.2); and a scale e^-30 to e^30 times the sample's spread.
        return 1e300
    sigma = math.exp(theta[2])
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
    one, held within [-1, 1]. Fitted in standard units from the Gumbel's moment estimates (sigma = sqrt(6) s / pi,
    mu = mean - 0.5772 sigma) by Nelder-Mead: scipy's own genextreme.fit, tried first, stalls
    at its starting location on such data (a shape of 0.00 for a sample of xi = 0.1). `start`: a
    fit to begin from instead (the bootstrap's refits start from the sample's own fit)."""
    from scipy.optimize import minimize
    x = np.asarray(maxima, float)
    if x.size < MIN_MAXIMA or not np.all(np.isfinite(x)):
        raise ValueError(f"gev_fit: needs at least {MIN_MAXIMA} finite maxima")
    if _distinct(x) < MIN_DISTINCT:
        raise ValueError(f"gev_fit: fewer than {MIN_DISTINCT} maxima distinct at {DISTINCT_RESOLUTION:g} of their "
                         "mean; no spread to fit (a load the ice does not move, set by the tug alone)")
    m, s = float(np.mean(x)), float(np.std(x))
    z = (x - m) / s
    sigma0 = math.sqrt(6.0) / math.pi
    starts = [[xi0, -0.5772 * sigma0, math.log(sigma0)] for xi0 in (-0.2, 0.0, 0.2)]
    if start is not None:
        starts = [[start["shape"], (start["loc"] - m) / s, math.log(start["scale"] / s)]]
    best = None
    for x0 in starts:
        r = minimize(_gev_nll, x0, args=(z,), method="Nelder-Mead",
                     options={"xatol": 1e-7, "fatol": 1e-10, "maxiter": 4000, "maxfev": 8000})
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
    Hinkley 1997): [{"period", "level", "lo", "hi"}], and the fit. ValueError with fewer than
    MIN_MAXIMA maxima or none that differ."""
    x = np.asarray(maxima, float)
    fit = gev_fit(x)
    rng = np.random.default_rng(seed)
    levels = {T: [] for T in periods}
    for _ in range(boot):
        sample = rng.choice(x, size=x.size, replace=True)
        if _distinct(sample) < MIN_DISTINCT:
            continue  # a resample of a few values has no spread to fit
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
        if v is None:  # none (no pull reaches the odds): an empty cell
            return ""
        if isinstance(v, float):
            return f"{v:.4g}"
        return str(v)
    out = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    out += ["| " + " | ".join(text(r.get(c, "")) for c in columns) + " |" for r in rows]
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------------------------------------
# A planning sweep: `floedem sweep` with a [decision] table (docs/sweeps.md, docs/towing.md)

#: The [decision] table's keys and what each allows.
DECISION_KEYS = {
    "no_parting": "true or false: a tow whose rope parted failed (default true)",
    "min_speed": "a number >= 0, m/s: the speed made good a tow must reach",
    "min_distance": "a number, m: the distance along the tow's direction it must reach",
    "max_stalled": "a number >= 0, s: the most time it may spend stalled",
    "probability": "a number in (0, 1): the odds the smallest pull must reach (default 0.9)",
    "pull": "a varied key: the tug's pull (default tow.bollard_pull when varied)",
    "periods": "a list of numbers > 1: return periods in tows (default [10, 100])",
}
#: The per-tow maxima a planning sweep fits: the rope's largest tension, and the largest
#: collision peak force on the towed body.
LOADS = ("tension_max", "collision_max")


def check_decision(decision, where, varied):
    """The sweep file's [decision] table checked; ValueError naming the key and what is allowed.
    Returns it with its defaults filled in."""
    if not isinstance(decision, dict):
        raise ValueError(f"{where}: decision: allowed a table")
    for k in decision:
        if k not in DECISION_KEYS:
            raise ValueError(f"{where}: decision.{k}: unknown key; allowed {', '.join(sorted(DECISION_KEYS))}")
    d = dict(no_parting=True, probability=0.9, periods=[10, 100])
    d.update(decision)
    number = (int, float)

    def bad(k):
        return ValueError(f"{where}: decision.{k}: {d[k]!r}; allowed {DECISION_KEYS[k]}")
    if not isinstance(d["no_parting"], bool):
        raise bad("no_parting")
    for k, ok in (("min_speed", lambda v: v >= 0), ("min_distance", lambda v: True), ("max_stalled", lambda v: v >= 0)):
        if k in d and not (isinstance(d[k], number) and not isinstance(d[k], bool) and math.isfinite(d[k]) and ok(d[k])):
            raise bad(k)
    if not (isinstance(d["probability"], number) and 0.0 < d["probability"] < 1.0):
        raise bad("probability")
    if not (isinstance(d["periods"], list) and d["periods"] and
            all(isinstance(p, number) and not isinstance(p, bool) and p > 1 for p in d["periods"])):
        raise bad("periods")
    if "pull" not in d and "tow.bollard_pull" in varied:
        d["pull"] = "tow.bollard_pull"
    if "pull" in d and d["pull"] not in varied:
        raise ValueError(f"{where}: decision.pull: {d['pull']!r}; allowed a key of [vary] "
                         f"({', '.join(varied) or 'none varied'})")
    return d


def run_record(run):
    """What a planning sweep keeps of one towing run: its outcome (json-ready) and the largest
    collision peak force on the towed body (0 when it met nothing). None for a run without a tow."""
    if run.tow is None or run.tow.outcome is None:
        return None
    o = dict(run.tow.outcome)
    o["direction"] = [float(x) for x in o["direction"]]
    names = list(run.bodies.name)
    towed = names.index(run.tow.attrs["body"]) if run.tow.attrs.get("body") in names else -1
    peak = 0.0
    if run.collisions is not None and len(run.collisions):
        mine = (run.collisions.body_a == towed) | (run.collisions.body_b == towed)
        if np.any(mine):
            peak = float(np.nanmax(run.collisions.peak_force[mine]))
    o["collision_max"] = peak
    return o


def _criteria(d):
    return {k: d[k] for k in ("no_parting", "min_speed", "min_distance", "max_stalled") if k in d}


def decide(summaries, keys, decision):
    """The planning sweep's rows, one per engine and point: the odds with their Wilson interval,
    and for each load and period its return level with a bootstrap interval (NaN with fewer than
    5 tows or no spread); and the smallest pull per engine and ice condition (the other keys)."""
    groups = {}
    for x in summaries:
        if x.get("tow") is None:
            raise ValueError(f"run {x['id']}: no tow outcome; a [decision] needs a towing scenario")
        groups.setdefault((x["engine"],) + tuple(json.dumps(x["point"][k]) for k in keys), []).append(x)
    rows = []
    for (engine, *point), runs in groups.items():
        row = dict(engine=engine, **{k: json.loads(p) for k, p in zip(keys, point)})
        row.update(odds([succeeded(r["tow"], **_criteria(decision)) for r in runs]))
        row["parted"] = sum(bool(r["tow"]["parted"]) for r in runs)
        for load in LOADS:
            maxima = [r["tow"][load] for r in runs]
            try:
                levels, _ = design_loads(maxima, periods=decision["periods"], boot=200)
            except ValueError:
                levels = [dict(period=T, level=math.nan, lo=math.nan, hi=math.nan) for T in decision["periods"]]
            row[f"{load}_mean"] = float(np.mean(maxima))
            for lv in levels:
                for q in ("level", "lo", "hi"):
                    row[f"{load}_{_period_text(lv['period'])}_{q}"] = lv[q]
        rows.append(row)
    smallest = []
    pull = decision.get("pull")
    if pull:
        others = [k for k in keys if k != pull]
        conditions = {}
        for r in rows:
            conditions.setdefault((r["engine"],) + tuple(json.dumps(r[k]) for k in others), []).append(r)
        for (engine, *cond), rs in conditions.items():
            pts = [(r[pull], r) for r in rs]
            smallest.append(dict(engine=engine, **{k: json.loads(c) for k, c in zip(others, cond)},
                                 probability=decision["probability"],
                                 pull_estimate=smallest_pull(pts, decision["probability"], conservative=False),
                                 pull_interval=smallest_pull(pts, decision["probability"])))
    return rows, smallest


def _period_text(T):
    return f"{T:g}"


def write_decisions(out, summaries, keys, decision):
    """OUT/decisions.csv (a row per engine and point), OUT/decisions.md (the tables to paste: the
    odds and design loads, and the smallest pull per ice condition), OUT/plots/towability.png
    (the odds against the pull, a line per ice condition), with two varied keys
    OUT/plots/towability_map_ENGINE.png (the odds over their grid), and
    OUT/plots/gev_LOAD_ENGINE_K.png (the quantile plot of point K's fit of each load).
    Returns (rows, smallest)."""
    rows, smallest = decide(summaries, keys, decision)
    columns = list(rows[0]) if rows else []
    tmp = os.path.join(out, "decisions.csv.partial")
    with open(tmp, "w", newline="") as f:
        f.write(csv_text(columns, rows))
    words = {"no_parting": lambda v: "the rope held" if v else None,
             "min_speed": lambda v: f"speed made good >= {v:g} m/s",
             "min_distance": lambda v: f"distance along the tow >= {v:g} m",
             "max_stalled": lambda v: f"stalled <= {v:g} s"}
    crit = ", ".join(w for w in (words[k](v) for k, v in _criteria(decision).items()) if w) or "every tow"
    T = [_period_text(p) for p in decision["periods"]]
    shown = ["engine"] + keys + ["n", "successes", "p", "lo", "hi", "parted"]
    loads = ["load"] + [f"{t} tows {q}" for t in T for q in ("level", "lo", "hi")]
    load_rows = [dict({k: r[k] for k in ["engine"] + keys}, load=load, **{f"{t} tows {q}": r[f"{load}_{t}_{q}"]
                                                                         for t in T for q in ("level", "lo", "hi")})
                 for r in rows for load in LOADS]
    text = [f"# Towing decisions\n\nSuccess: {crit}. Odds with their Wilson 95 % interval:\n", table(rows, shown),
            f"\nDesign loads (N): the line's largest tension (`tension_max`) and the largest collision peak force on "
            f"the towed body (`collision_max`) exceeded once in {' and '.join(T)} tows, from a GEV fit of the tows' "
            f"maxima with its bootstrap 95 % interval (nan: fewer than {MIN_MAXIMA} tows, or fewer than "
            f"{MIN_DISTINCT} maxima distinct at {DISTINCT_RESOLUTION:g} of their mean: a load the ice does not move):\n",
            table(load_rows, ["engine"] + keys + loads)]
    if smallest:
        text += [f"\nThe smallest `{decision['pull']}` whose odds reach {decision['probability']:g} (the estimate, "
                 "and the interval's lower end; empty: none of the pulls tried):\n",
                 table(smallest, list(smallest[0]))]
    write_text = "\n".join(text)
    with open(os.path.join(out, "decisions.md.partial"), "w") as f:
        f.write(write_text)
    _decision_plots(out, rows, summaries, keys, decision)
    os.replace(os.path.join(out, "decisions.md.partial"), os.path.join(out, "decisions.md"))
    os.replace(tmp, os.path.join(out, "decisions.csv"))
    return rows, smallest


def _decision_plots(out, rows, summaries, keys, decision):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(os.path.join(out, "plots"), exist_ok=True)
    pull = decision.get("pull")
    x_key = pull or (keys[0] if keys else None)
    others = [k for k in keys if k != x_key]
    fig, ax = plt.subplots(figsize=(6.5, 4))
    lines = {}
    for r in rows:
        lines.setdefault((r["engine"],) + tuple(json.dumps(r[k]) for k in others), []).append(r)
    for (engine, *cond), rs in lines.items():
        rs.sort(key=lambda r: r[x_key] if x_key else 0)
        x = [r[x_key] if x_key else 0 for r in rs]
        p = np.array([r["p"] for r in rs])
        err = [p - np.array([r["lo"] for r in rs]), np.array([r["hi"] for r in rs]) - p]
        label = engine + "".join(f", {k}={json.loads(c)}" for k, c in zip(others, cond))
        ax.errorbar(x, p, yerr=err, marker="o", capsize=3, label=label)
    ax.axhline(decision["probability"], color="k", lw=0.6, ls="--")
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel(x_key or "")
    ax.set_ylabel("probability of success (Wilson 95 %)")
    ax.set_title("Towability")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "plots", "towability.png"), dpi=100)
    plt.close(fig)
    numeric = [k for k in keys if all(isinstance(r[k], (int, float)) and not isinstance(r[k], bool) for r in rows)]
    if len(keys) == 2 and len(numeric) == 2:
        # The towability map: the odds over the grid of two varied keys (the pull across).
        x_key = x_key if x_key in numeric else numeric[0]
        y_key = next(k for k in numeric if k != x_key)
        for engine in sorted({r["engine"] for r in rows}):
            mine = [r for r in rows if r["engine"] == engine]
            xs, ys = sorted({r[x_key] for r in mine}), sorted({r[y_key] for r in mine})
            grid = np.full((len(ys), len(xs)), np.nan)
            for r in mine:
                grid[ys.index(r[y_key]), xs.index(r[x_key])] = r["p"]
            fig, ax = plt.subplots(figsize=(1.2 * len(xs) + 2.5, 0.8 * len(ys) + 1.8))
            im = ax.imshow(grid, origin="lower", cmap="RdYlGn", vmin=0.0, vmax=1.0, aspect="auto")
            for r in mine:
                ax.text(xs.index(r[x_key]), ys.index(r[y_key]), f"{r['p']:.2f}\n[{r['lo']:.2f}, {r['hi']:.2f}]",
                        ha="center", va="center", fontsize=7)
            ax.set_xticks(range(len(xs)), [f"{v:g}" for v in xs])
            ax.set_yticks(range(len(ys)), [f"{v:g}" for v in ys])
            ax.set_xlabel(x_key)
            ax.set_ylabel(y_key)
            ax.set_title(f"Towability, {engine}: probability of success [Wilson 95 %]", fontsize=8)
            fig.colorbar(im, ax=ax)
            fig.tight_layout()
            fig.savefig(os.path.join(out, "plots", f"towability_map_{engine}.png"), dpi=100)
            plt.close(fig)
    groups = {}
    for x in summaries:
        groups.setdefault((x["engine"],) + tuple(json.dumps(x["point"][k]) for k in keys), []).append(x)
    for n, ((engine, *point), runs) in enumerate(groups.items()):
        for load in LOADS:
            maxima = [r["tow"][load] for r in runs]
            try:
                fit = gev_fit(maxima)
            except ValueError:
                continue
            fig, ax = plt.subplots(figsize=(4, 4))
            quantile_plot(maxima, fit, ax)
            ax.set_title(f"{load}: {engine}" + "".join(f", {k}={json.loads(p)}" for k, p in zip(keys, point)),
                         fontsize=7)
            fig.tight_layout()
            fig.savefig(os.path.join(out, "plots", f"gev_{load}_{engine}_{n}.png"), dpi=100)
            plt.close(fig)
