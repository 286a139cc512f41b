"""bench/soak.py's leak figure: the slope of the daemon's resident memory against time after
the warm-up, by least squares, with a 95 % confidence interval (Student t from the residuals).

RSS samples taken every few seconds are strongly autocorrelated (a frame's buffers, a LUT
rebuild, glibc's arenas swing RSS for tens of seconds), so a fit on the raw samples would give
an interval far too narrow. The fit is made on block means (--slope-block-s real seconds each,
60 by default: about 30 samples), and the residuals of that fit are checked for the
autocorrelation that is left: when their lag-1 autocorrelation r is positive, the number of
blocks n becomes an effective sample size n_eff = n (1 - r) / (1 + r), the standard error is
scaled by sqrt((n - 2) / (n_eff - 2)) and the t quantile taken at n_eff - 2 degrees of freedom.

Samples of different daemon processes (a kill -9 and a restart) are never mixed in one block;
the fit has one intercept per process and a common slope (the within-process slope)."""

import math

# Student t 0.975 quantiles for 1..30 degrees of freedom.
_T975 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179,
         2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
         2.060, 2.056, 2.052, 2.048, 2.045, 2.042]


def t975(df):
    """The 0.975 quantile of Student's t with df degrees of freedom (df may be fractional:
    the table's value at its floor, which is the larger, so the interval errs on the wide
    side; above 30 the Cornish-Fisher expansion, within 1e-3)."""
    if df < 1:
        return math.inf
    if df <= 30:
        return _T975[int(math.floor(df)) - 1]
    z = 1.959964
    return (z + (z ** 3 + z) / (4 * df) + (5 * z ** 5 + 16 * z ** 3 + 3 * z) / (96 * df ** 2)
            + (3 * z ** 7 + 19 * z ** 5 + 17 * z ** 3 - 15 * z) / (384 * df ** 3))


def block_means(samples, block_s):
    """samples: (t, value, process) in time order -> (t mean, value mean, process) per block
    of block_s seconds of one process (a last block shorter than half a block is dropped)."""
    out = []
    cur = []

    def flush():
        if cur and (cur[-1][0] - cur[0][0] >= block_s * 0.5 or not out):
            out.append((sum(s[0] for s in cur) / len(cur), sum(s[1] for s in cur) / len(cur),
                        cur[0][2]))
    for s in samples:
        if cur and (s[2] != cur[0][2] or s[0] - cur[0][0] >= block_s):
            flush()
            cur = []
        cur.append(s)
    flush()
    return out


def measured_stretch(rows, skip_s):
    """The rows (real s first, phase fourth) of the measured random changes after their first
    skip_s: the settle before the stretch holds the reference state and the home views, less
    than the random changes' working set, and the first minutes climb back to it."""
    measured = [r for r in rows if r[3] == "random"]
    return [r for r in measured if r[0] >= measured[0][0] + skip_s] if measured else []


def fit_slope(samples, block_s):
    """The within-process least-squares slope of value against t (units per second) on block
    means, with its 95 % interval. Returns a dict: slope, low, high, n (blocks), n_eff, r1
    (lag-1 autocorrelation of the residuals), df, t; None with fewer than 4 blocks."""
    blocks = block_means(samples, block_s)
    n = len(blocks)
    groups = {}
    for t, v, p in blocks:
        groups.setdefault(p, []).append((t, v))
    k = len(groups)  # one intercept per process
    if n - k - 1 < 2:
        return None
    sxx = sxy = 0.0
    means = {}
    for p, g in groups.items():
        mt = sum(t for t, _ in g) / len(g)
        mv = sum(v for _, v in g) / len(g)
        means[p] = (mt, mv)
        sxx += sum((t - mt) ** 2 for t, _ in g)
        sxy += sum((t - mt) * (v - mv) for t, v in g)
    if sxx <= 0:
        return None
    slope = sxy / sxx
    resid = [v - means[p][1] - slope * (t - means[p][0]) for t, v, p in blocks]
    df = n - k - 1
    s2 = sum(e * e for e in resid) / df
    se = math.sqrt(s2 / sxx)
    r1 = 0.0
    ss = sum(e * e for e in resid)
    if ss > 0 and n > 2:
        r1 = sum(resid[i] * resid[i + 1] for i in range(n - 1)
                 if blocks[i][2] == blocks[i + 1][2]) / ss
    n_eff = float(n)
    if r1 > 0:
        n_eff = n * (1 - r1) / (1 + r1)
        df_eff = n_eff - k - 1
        if df_eff < 1:
            return {"slope": slope, "low": -math.inf, "high": math.inf, "n": n,
                    "n_eff": n_eff, "r1": r1, "df": df_eff, "t": math.inf}
        se *= math.sqrt(df / df_eff)
        df = df_eff
    t = t975(df)
    return {"slope": slope, "low": slope - t * se, "high": slope + t * se, "n": n,
            "n_eff": n_eff, "r1": r1, "df": df, "t": t}
