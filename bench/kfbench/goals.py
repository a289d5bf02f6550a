"""The goals of the bench, each with its measured value: MET / NOT MET, or NOT MEASURED when its
part did not run. The wording is in the template (blocks goal_*)."""
from .common import BLOCK, FORCE_FRAME_MS, SR
from .native import LAG_GOAL, reconstruction_checks
from .spatial import LONG_LABEL
from .template import render

SPATIAL_GOAL = 0.8  # SpatialBufRd cubic's CPU over BufRd cubic's
LOUDNESS_GOAL = 0.5  # LoudnessToFriction's CPU over the RunningSum chain's
LOUDNESS_ERROR_GOAL_N = 1e-6
ERROR_GOAL_TEXT = f"{LOUDNESS_ERROR_GOAL_N:.0e}".replace("e-0", "e-")  # as the prose writes it: 1e-6
FORCE_GOAL_MS = FORCE_FRAME_MS + BLOCK / SR * 1e3  # one force frame + one audio block
JITTER_GOAL_MS = 0.2  # the loop period's p99 beyond one frame
# The paper's tactile output latency, and a ceiling for the worst frame, with realtime scheduling
# under load at 48 kHz / 64 (rtload).
LOADED_P99_GOAL_MS = 2.4
LOADED_MAX_GOAL_MS = 4.0


def _status(met):
    return "MET" if met else "NOT MET"


def _values(values, digits=3, scale=1.0):
    return ", ".join(f"{v * scale:.{digits}f}" for v in values)


def _where(tm):
    """The code path and processor a timing render ran on (older results: '?')."""
    return {"path": tm.get("core_path", "?"), "processor": tm.get("processor", "?")}


def spatial_modes(tm):
    """SpatialBufRd none and linear against BufRd with the same interpolation (CPU only: their
    errors are the same kernels', see the spatial section)."""
    if not tm:
        return render("goal_spatial_modes_unmeasured", goal=SPATIAL_GOAL)
    modes = {m: tm["ratios"][f"SpatialBufRd/BufRd {m}"]["cpu-empty"] for m in ("none", "linear")}
    return render("goal_spatial_modes", goal=SPATIAL_GOAL, **_where(tm),
                  status=_status(all(e["median"] <= SPATIAL_GOAL for e in modes.values())),
                  ratios=", ".join(f"{m} {e['median']:.3f}x [{e['min']:.3f}..{e['max']:.3f}]" for m, e in modes.items()))


def spatial(tm, sp):
    if not (tm and sp):
        return render("goal_spatial_unmeasured", goal=SPATIAL_GOAL)
    e = tm["ratios"]["SpatialBufRd/BufRd cubic"]["cpu-empty"]
    long = sp["index"][LONG_LABEL]
    return render("goal_spatial", goal=SPATIAL_GOAL, **_where(tm), status=_status(e["median"] <= SPATIAL_GOAL), cpu=e,
                  source=tm["ratios"]["SpatialBufRd/BufRd cubic"]["cpu-source"]["median"],
                  worst=max(en["SpatialBufRd cubic"]["max_vs_signal"] for en in sp["pilot"].values()),
                  worst_bufrd=max(en["BufRd cubic"]["max_vs_signal"] for en in sp["pilot"].values()),
                  index=long["SpatialBufRd cubic"]["max_index_error"],
                  index_bufrd=long["BufRd cubic"]["max_index_error"])


def loudness(tm, ld):
    if not (tm and ld):
        return render("goal_loudness_unmeasured", goal=LOUDNESS_GOAL, error_goal=ERROR_GOAL_TEXT)
    e = tm["ratios"]["LoudnessToFriction/RunningSum chain"]["cpu-empty"]
    err = ld["errors"]["LoudnessToFriction"]["max_n"]
    return render("goal_loudness", goal=LOUDNESS_GOAL, error_goal=ERROR_GOAL_TEXT, **_where(tm),
                  status=_status(e["median"] <= LOUDNESS_GOAL and err <= LOUDNESS_ERROR_GOAL_N), cpu=e,
                  source=tm["ratios"]["LoudnessToFriction/RunningSum chain"]["cpu-source"]["median"], error=err)


def reconstruction(rc):
    if not rc:
        return render("goal_reconstruction_unmeasured", goal=LAG_GOAL)
    checks = reconstruction_checks(rc)
    return render("goal_reconstruction", goal=LAG_GOAL, status=_status(all(c["met"] for c in checks)),
                  movements="; ".join(render("goal_reconstruction_movement", **c) for c in checks))


def realtime(e2e):
    if not e2e:
        return [render("goal_force_unmeasured", goal_ms=FORCE_GOAL_MS),
                render("goal_jitter_unmeasured", goal_us=JITTER_GOAL_MS * 1e3)]
    runs = e2e["runs"]
    p99 = [r["force to magnet"]["p99_ms"] for r in runs]
    jitter = [r["loop period"]["p99_ms"] - FORCE_FRAME_MS for r in runs]
    return [render("goal_force", goal_ms=FORCE_GOAL_MS, frame_ms=FORCE_FRAME_MS,
                   status=_status(max(p99) <= FORCE_GOAL_MS), p99=_values(p99),
                   max=_values(r["force to magnet"]["max_ms"] for r in runs), runs=len(runs)),
            render("goal_jitter", goal_us=JITTER_GOAL_MS * 1e3, frame_ms=FORCE_FRAME_MS,
                   loop_khz=1 / FORCE_FRAME_MS,
                   status=_status(max(jitter) <= JITTER_GOAL_MS), jitter_us=_values(jitter, 0, 1e3), runs=len(runs),
                   period_max=_values(r["loop period"]["max_ms"] for r in runs))]


def loaded(rt):
    if not rt:
        return render("goal_loaded_unmeasured", p99=LOADED_P99_GOAL_MS, max=LOADED_MAX_GOAL_MS)
    run = next(r for r in rt["runs"] if r["rate"] == 48000 and r["period"] == 64 and r["realtime"] and r["loaded"])
    f = run["force"]
    missed = f["skippedFrames"] + f["frameQueueOverflows"]
    met = (f["forceP99S"] * 1e3 <= LOADED_P99_GOAL_MS and f["forceMaxS"] * 1e3 <= LOADED_MAX_GOAL_MS
           and f["watchdogTrips"] == 0 and missed == 0)
    witness = run.get("witness")
    return render("goal_loaded", p99=LOADED_P99_GOAL_MS, max=LOADED_MAX_GOAL_MS, status=_status(met),
                  got_p99=f["forceP99S"] * 1e3, got_max=f["forceMaxS"] * 1e3, trips=f["watchdogTrips"],
                  missed=missed, load=rt["load"],
                  machine=f"{witness['max_us'] / 1e3:.3f} ms" if witness else "not measured (no cyclictest)")


def goals(results):
    """The goal lines, printed by the run and listed at the top of the report."""
    return [spatial(results.get("timing"), results.get("spatial")), spatial_modes(results.get("timing")),
            loudness(results.get("timing"), results.get("loudness")),
            reconstruction(results.get("reconstruction")),
            *realtime(results.get("e2e")), loaded(results.get("rtload"))]
