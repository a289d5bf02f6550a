"""Debian's psignifit (package psignifit 2.5.6: Wichmann and Hill's engine as the command-line
program /usr/bin/psignifit; no Python or MATLAB binding is packaged) as the reference for the
psychometric fits of the bench and the tests, which install it; the product does not need it.

It is given the answers grouped by level (x, right, n) and a batch of preferences: the Weibull
F(x) = 1 - exp(-(x / alpha) ^ beta), two intervals (gamma fixed at 1/2), lambda (the lapse rate)
free within its default limits [0, 0.05], the slope beta
within [0.2, 20] (unbounded, sparse staircase data let it run to a step), no bootstrap (#RUNS 0): the same model and bounds as
kfstudy.psychometric.fit, so alpha is the threshold of both."""
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from kfstudy import psychometric

PROGRAM = "/usr/bin/psignifit"
PREFERENCES = """#shape Weibull
#n_intervals 2
#runs 0
#matrix_format xrn
#verbose false
#beta_limits 0.2, 20
#write_pa_est stdout
"""


def available():
    return shutil.which(PROGRAM) is not None


def fit(levels, correct):
    """psignifit's maximum-likelihood Weibull of trials: dict(threshold, slope, guess, lapse)."""
    x, right, total = psychometric.grouped(levels, correct)
    with tempfile.TemporaryDirectory(prefix="kf-psignifit-") as folder:
        data, prefs = Path(folder) / "data.txt", Path(folder) / "prefs.txt"
        data.write_text("".join(f"{a!r} {r} {n}\n" for a, r, n in zip(x, right, total)))
        prefs.write_text(PREFERENCES)
        out = subprocess.run([PROGRAM, str(data), str(prefs)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True, timeout=60)
    if out.returncode != 0:
        raise RuntimeError(f"psignifit failed ({out.returncode}): {out.stderr.strip()}")
    alpha, beta, gamma, lapse = (float(v) for v in out.stdout.strip().splitlines()[0].split(","))
    return dict(threshold=alpha, slope=beta, guess=gamma, lapse=lapse) if np.isfinite(alpha) else None
