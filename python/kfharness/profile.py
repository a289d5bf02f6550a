"""The paper's profile (profiles/paper.json): the device's numbers, the friction mapping of
equations (1)-(2) and the pilot signal. C++ and sclang get the same file through CMake."""
import functools
import json

from . import paths


@functools.lru_cache(maxsize=None)
def _load():
    return json.loads((paths.REPO_DIR / "profiles" / "paper.json").read_text())


def device():
    """countMm, updateRateHz, minForceN, maxForceN, audioLatencyS, ... (a copy)."""
    return dict(_load()["device"])


def mapping():
    """windowS, loDb, hiDb, loForceN, hiForceN, ref, maxWindowS (a copy)."""
    return dict(_load()["mapping"])


def pilot():
    """signalFrames, cycleFrames and mappingNSamplesPerMm (a copy)."""
    return dict(_load()["pilot"])


def max_speed_mm_per_s(spec=None):
    """Counts x count size x update rate: 333.375 mm/s for the paper's device (it says 334)."""
    spec = spec or device()
    return spec["maxCountsPerReport"] * spec["countMm"] * spec["updateRateHz"]


def audio_delay_s(spec=None):
    """Audio is delayed by tactile less audio latency so sound and touch arrive together."""
    spec = spec or device()
    return spec["tactileLatencyS"] - spec["audioLatencyS"]
