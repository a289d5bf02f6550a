"""The psychometric fit of the threshold procedures: maximum likelihood of the Weibull that the
sclang classes use (FrictionPsychometric), with a free lapse rate and the guess rate fixed (1/2 for
two intervals), its plot, and the threshold section of a study's report from a session's trials CSV
(one row per trial, as FrictionThreshold's onTrial events give them: at least `level` and
`correct`; a `condition` column, when there is one, gives one fit per condition).

    p(x) = guess + (1 - guess - lapse) * (1 - exp(-(x / threshold) ** slope))

The fit maximises the binomial likelihood of the answers over log threshold, log slope and
lapse in [0, max_lapse] (0.05 by default, as Debian's psignifit bounds it) with scipy's L-BFGS-B,
started from the best point of a coarse grid so that a flat or sparse data set still finds the
global maximum. The bench (scripts/bench.sh --only thresholds) checks it against psignifit.
"""
from pathlib import Path

import numpy as np

from . import checked_csv

GUESS_2AFC = 0.5
MAX_LAPSE = 0.05


def weibull(level, threshold, slope, guess=GUESS_2AFC, lapse=0.0):
    level = np.asarray(level, dtype=float)
    return guess + (1 - guess - lapse) * (1 - np.exp(-(level / threshold) ** slope))


def level_at(p, threshold, slope, guess=GUESS_2AFC, lapse=0.0):
    """The level answered right with probability p (guess < p < 1 - lapse): weibull's inverse."""
    fraction = (p - guess) / (1 - guess - lapse)
    if not 0 < fraction < 1:
        raise ValueError(f"p must lie between guess {guess} and 1 - lapse {1 - lapse}, got {p}")
    return threshold * (-np.log1p(-fraction)) ** (1 / slope)


def grouped(levels, correct):
    """(levels, right, total) per distinct level, ascending."""
    levels, correct = np.asarray(levels, dtype=float), np.asarray(correct, dtype=bool)
    unique = np.unique(levels)
    right = np.array([np.count_nonzero(correct[levels == u]) for u in unique])
    total = np.array([np.count_nonzero(levels == u) for u in unique])
    return unique, right, total


def _negative_log_likelihood(params, x, right, total, guess):
    log_t, log_b, lapse = params
    p = np.clip(weibull(x, np.exp(log_t), np.exp(log_b), guess, lapse), 1e-12, 1 - 1e-12)
    return -np.sum(right * np.log(p) + (total - right) * np.log1p(-p))


# Fewer trials than this and a 2AFC threshold is poorly determined whatever the procedure: the
# report says so beside the fit (its standard error says by how much).
MIN_TRIALS = 20
# The optimiser starts from this many of the best grid points: the likelihood of a few trials
# has several maxima (a steep curve between two levels, a lapse against a shallow slope).
STARTS = 8


def _bounds(x, max_lapse):
    lo, hi = np.log(x.min() / 2), np.log(x.max() * 2)
    return [(lo - 2, hi + 2), (np.log(0.2), np.log(20)), (0.0, max_lapse)]


def _se_log10_threshold(params, x, right, total, guess, bounds):
    """The standard error of log10 threshold from the observed information (the likelihood's
    curvature at its maximum), over the parameters not at a bound; inf where it is flat."""
    free = [i for i, (a, b) in enumerate(bounds) if i == 0 or not (np.isclose(params[i], a) or np.isclose(params[i], b))]
    steps = np.array([1e-4, 1e-4, 1e-5])
    def f(p):
        return _negative_log_likelihood(p, x, right, total, guess)
    hessian = np.zeros((len(free), len(free)))
    for m, i in enumerate(free):
        for n, j in enumerate(free):
            di, dj = np.eye(3)[i] * steps[i], np.eye(3)[j] * steps[j]
            hessian[m, n] = (f(params + di + dj) - f(params + di - dj) - f(params - di + dj)
                             + f(params - di - dj)) / (4 * steps[i] * steps[j])
    try:
        variance = np.linalg.inv(hessian)[0, 0]
    except np.linalg.LinAlgError:
        return float("inf")
    return float(np.sqrt(variance) / np.log(10)) if variance > 0 else float("inf")


def fit(levels, correct, guess=GUESS_2AFC, max_lapse=MAX_LAPSE):
    """The maximum-likelihood Weibull of trials (a level > 0 and a right/wrong answer each): a dict
    of threshold, slope, lapse, guess, the log-likelihood, the number of trials, the levels at
    70.7 %, 75 % and 79.4 % correct (Levitt's staircases' and the midpoint's), threshold_se_log10
    (the standard error of log10 threshold) and warning (why the fit says little, or "")."""
    from scipy.optimize import minimize

    x, right, total = grouped(levels, correct)
    if len(x) == 0 or np.any(x <= 0):
        raise ValueError("fit needs at least one trial, every level > 0")
    bounds = _bounds(x, max_lapse)
    # Thresholds over the levels' range and beyond it by a factor of 2 each way, slopes and lapse
    # rates over their whole bounds: a few trials' maximum often lies at a steep slope with the
    # highest lapse rate (a wrong answer at a high level), which no start at slope 6 or below
    # reached (2 of the study job's 15 fits, 0.12 and 0.41 log-likelihood below it).
    starts = [(t, b, lapse) for t in np.linspace(bounds[0][0] + 2, bounds[0][1] - 2, 25)
              for b in np.log([0.5, 1, 2, 3.5, 6, 10, 20]) for lapse in (0.0, max_lapse / 2, max_lapse)]
    starts.sort(key=lambda s: _negative_log_likelihood(s, x, right, total, guess))
    result = min((minimize(_negative_log_likelihood, start, args=(x, right, total, guess), method="L-BFGS-B",
                           bounds=bounds) for start in starts[:STARTS]), key=lambda r: r.fun)
    threshold, slope, lapse = float(np.exp(result.x[0])), float(np.exp(result.x[1])), float(result.x[2])
    trials = int(total.sum())
    se = _se_log10_threshold(np.array(result.x, dtype=float), x, right, total, guess, bounds)
    warning = ""
    if trials < MIN_TRIALS:
        warning = f"only {trials} trials (fewer than {MIN_TRIALS}): the threshold is poorly determined"
    elif not np.isfinite(se):
        warning = "the likelihood is flat along the threshold: the trials do not determine it"
    out = dict(threshold=threshold, slope=slope, lapse=lapse, guess=guess, log_likelihood=float(-result.fun),
               trials=trials, threshold_se_log10=se, warning=warning)
    for name, p in (("level_707", 0.5 ** 0.5), ("level_750", 0.75), ("level_794", 0.5 ** (1 / 3))):
        out[name] = float(level_at(p, threshold, slope, guess, lapse)) if p < 1 - lapse else float("nan")
    return out


def cramer_rao_sd_log10(levels, threshold, slope, guess=GUESS_2AFC, lapse=0.0):
    """The theory's smallest sd of an unbiased log10 threshold from trials at these levels (one a
    trial), all three parameters (log threshold, log slope, lapse) unknown, at the given values of
    the observer: the Fisher information of the binomial answers, inverted. A fit held within
    bounds (the lapse rate's, the slope's) can vary less than this where few trials sit on the
    curve's flanks, and be biased."""
    x = np.asarray(levels, dtype=float)
    t, b, g, lam = threshold, slope, guess, lapse
    u = (x / t) ** b
    p = weibull(x, t, b, g, lam)
    grad = np.stack([-(1 - g - lam) * np.exp(-u) * u * b,             # d p / d ln t
                     (1 - g - lam) * np.exp(-u) * u * b * np.log(x / t),  # d p / d ln b
                     -(1 - np.exp(-u))])                               # d p / d lapse
    info = (grad / (p * (1 - p))) @ grad.T
    try:
        return float(np.sqrt(np.linalg.inv(info)[0, 0]) / np.log(10))
    except np.linalg.LinAlgError:
        return float("inf")


def plot(levels, correct, fitted, path, title="", xlabel="level", observer=None):
    """The answers (proportion right per level, dot area by trials) and the fitted curve; with
    observer (a dict of threshold, slope, lapse: a simulated participant's), its curve dashed."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x, right, total = grouped(levels, correct)
    fig, ax = plt.subplots(figsize=(6, 4))
    curve_x = np.geomspace(x.min() / 2, x.max() * 2, 300)
    ax.plot(curve_x, weibull(curve_x, fitted["threshold"], fitted["slope"], fitted["guess"], fitted["lapse"]),
            color="C0", label=f"Weibull: threshold {fitted['threshold']:.3g}, slope {fitted['slope']:.2g}, "
                              f"lapse {fitted['lapse']:.2g}")
    if observer:
        ax.plot(curve_x, weibull(curve_x, observer["threshold"], observer["slope"], fitted["guess"], observer["lapse"]),
                color="0.4", ls="--", label=f"model observer: threshold {observer['threshold']:.3g}")
    ax.scatter(x, right / total, s=12 + 60 * total / total.max(), color="C1", zorder=3, label="answers per level")
    ax.axvline(fitted["threshold"], color="C0", ls=":")
    ax.axhline(fitted["guess"], color="0.6", lw=0.8)
    ax.set_xscale("log")
    ax.set_ylim(0, 1.02)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("proportion correct")
    ax.set_title(title)
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def read_trials(path, damaged=None):
    """The rows of a trials CSV as dicts, with level a float and correct a bool (true/false, 1/0);
    damaged rows are skipped and listed in `damaged` (checked_csv)."""
    rows = checked_csv.read_rows(path, damaged)
    for row in rows:
        row["level"] = float(row["level"])
        row["correct"] = str(row["correct"]).strip().lower() in ("true", "1", "yes")
    return rows


def procedure_trials(rows):
    """The trials a condition's procedure used, and how its attempts were joined. A resumed
    attempt continues the procedure from the trials stored before it (FrictionStudySession), so
    they are, per trial number, the row of the latest attempt that has it, up to the last
    attempt's last trial. Returns (rows in trial order, text such as "trials 1-8 of attempt 1,
    9-20 of attempt 2"). Rows without attempt and trial columns are all used, in their order."""
    if not rows or any(r.get("attempt") in (None, "") or r.get("trial") in (None, "") for r in rows):
        return rows, ""
    last_attempt = max(int(r["attempt"]) for r in rows)
    last_trial = max(int(r["trial"]) for r in rows if int(r["attempt"]) == last_attempt)
    by_trial = {}
    for row in sorted(rows, key=lambda r: int(r["attempt"])):
        by_trial[int(row["trial"])] = row
    used = [by_trial[n] for n in sorted(by_trial) if n <= last_trial]
    parts = []
    for row in used:
        if parts and parts[-1][2] == row["attempt"]:
            parts[-1][1] = row["trial"]
        else:
            parts.append([row["trial"], row["trial"], row["attempt"]])
    return used, ", ".join(f"trials {a}-{b} of attempt {k}" for a, b, k in parts)


def report_section(trials_csv, out_dir, name=None, conditions=None, damaged=None):
    """The threshold section of a report from one session's trials CSV: a PNG per condition
    (<name>-<condition>-psychometric.png in out_dir) and the Markdown that shows them, with the
    figures' names relative to out_dir. conditions: per condition name, what else is known of it
    (an Event of the session's log): unit (of the levels), estimate (the procedure's own) and
    observer (a simulated participant's model observer: its threshold, slope and lapse, shown
    beside the fit). Returns (Markdown, a dict per condition: condition, unit, the fit's keys,
    estimate and observer_threshold, nan where unknown)."""
    trials_csv, out_dir = Path(trials_csv), Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    name = name or trials_csv.stem
    conditions = conditions or {}
    rows = read_trials(trials_csv, damaged)
    lines = [f"### Thresholds: {name}", "",
             "Maximum-likelihood Weibull, guess rate 1/2, lapse rate free in [0, 0.05] (kfstudy.psychometric); "
             "the procedure's own estimate beside it, and a simulated participant's known threshold (its model "
             "observer's).", "",
             "| condition | trials | threshold | its standard error (log10) | slope | lapse | level at 70.7 % "
             "| at 79.4 % | procedure's estimate | model observer's threshold | figure |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    fits, warnings, notes = [], [], []
    for condition in sorted({r.get("condition") or "" for r in rows}):
        chosen, joined = procedure_trials([r for r in rows if (r.get("condition") or "") == condition])
        if len({r.get("attempt") for r in chosen}) > 1:
            notes.append(f"{condition}: {joined} (a resumed attempt continues the procedure; the fit takes "
                         "exactly the trials it used).")
        levels, correct = [r["level"] for r in chosen], [r["correct"] for r in chosen]
        known = conditions.get(condition, {})
        unit = known.get("unit") or ""
        fitted = fit(levels, correct)
        png = f"{name}-{condition or 'all'}-psychometric.png"
        plot(levels, correct, fitted, out_dir / png, title=f"{name} {condition}".strip(),
             xlabel=f"level ({unit})" if unit else "level", observer=known.get("observer"))
        estimate = float((known.get("estimate") or {}).get("threshold") or "nan")
        observer = float((known.get("observer") or {}).get("threshold") or "nan")
        fits.append(dict(condition=condition, unit=unit, **fitted, estimate=estimate, observer_threshold=observer))
        lines.append(f"| {condition or '-'} | {fitted['trials']} | {fitted['threshold']:.4g} {unit} | "
                     f"{fitted['threshold_se_log10']:.3f} | {fitted['slope']:.3g} | {fitted['lapse']:.3f} | "
                     f"{fitted['level_707']:.4g} | {fitted['level_794']:.4g} | {estimate:.4g} | {observer:.4g} "
                     f"| ![]({png}) |")
        if fitted["warning"]:
            warnings.append(f"**{condition or '-'}: {fitted['warning']}.**")
    lines += [""] + warnings if warnings else []
    lines += [""] + notes if notes else []
    return "\n".join(lines) + "\n", fits
