"""Debian's python3-questplus (2019.4) as the reference for FrictionQuestPlus, for the bench and
the tests, which install it (the product does not need it). The same Weibull (its 'linear' stimulus
scale is FrictionPsychometric's form), grid, flat prior, 'min_entropy' selection and posterior-mean
estimates as FrictionQuestPlus's defaults."""
import warnings

import numpy as np


def log_levels(lo, hi, count):
    """FrictionPsychometric.logLevels, to the same bits: lo * (hi / lo) ** (i / (count - 1))."""
    return [lo * (hi / lo) ** (i / (count - 1)) for i in range(count)]


# FrictionQuestPlus's default grid for levels from lo to hi.
def default_grid(levels):
    return dict(thresholds=log_levels(min(levels), max(levels), 40), slopes=[1.5, 2, 3, 4, 6], lapses=[0, 0.02, 0.04])


def _next(q):
    """q.next_intensity without numpy's warnings: questplus takes log 0 for grid points the
    answers ruled out (its sums skip the nan they make), once per trial."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return q.next_intensity


def make(levels, grid=None, guess=0.5):
    from questplus import QuestPlusWeibull

    grid = grid or default_grid(levels)
    return QuestPlusWeibull(intensities=list(levels), thresholds=grid["thresholds"], slopes=grid["slopes"],
                            lower_asymptotes=[guess], lapse_rates=grid["lapses"], responses=["correct", "wrong"],
                            stim_scale="linear", stim_selection_method="min_entropy", param_estimation_method="mean")


def _estimate(q):
    e = q.param_estimate
    return dict(threshold=e["threshold"], slope=e["slope"], lapse=e["lapse_rate"])


def replay(levels, trial_levels, correct, grid=None):
    """Gives questplus the trials of one of our runs: the level questplus would choose before each
    trial and its estimate after them all."""
    q = make(levels, grid)
    chosen = []
    for level, right in zip(trial_levels, correct):
        chosen.append(_next(q))
        # sclang posts 14 digits: the grid's level nearest to the one given.
        nearest = levels[int(np.argmin(np.abs(np.asarray(levels) - level)))]
        q.update(intensity=nearest, response="correct" if right else "wrong")
    return chosen, _estimate(q)


def simulate(levels, observer, trials, checkpoints, seed, grid=None):
    """One run of questplus against the observer (numpy's random numbers, seeded): its estimates
    at the checkpoints (numbers of trials)."""
    from kfstudy import psychometric

    rng = np.random.default_rng(seed)
    q = make(levels, grid)
    estimates = {}
    for n in range(1, trials + 1):
        level = _next(q)
        p = psychometric.weibull(level, observer["threshold"], observer["slope"], observer["guess"], observer["lapse"])
        q.update(intensity=level, response="correct" if rng.random() < p else "wrong")
        if n in checkpoints:
            estimates[n] = _estimate(q)
    return estimates
