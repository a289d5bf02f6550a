"""What every realtime test file shares: `jack`, a JACK server of its own on the dummy driver
(unique name), started for the test and stopped after it by its process; `display`, a virtual X
display of its own for the windows' tests. Where this user may
use realtime scheduling it runs as a performer's would (`jackd -R`): its and scsynth's audio
threads SCHED_FIFO, and the device's threads above them (ThreadScheduling), so that the tests'
timing holds on a busy machine (scripts/realtime-under-load.sh)."""
import pytest

from kfharness.jack import JackServer
from kfharness.load import realtime_allowed
from kfharness.xvfb import Xvfb

REALTIME_PRIORITY = 70  # jackd -R -P 70: scsynth's audio thread at 65, the device threads at 66


def performer_jack():
    """A JACK server as a performer runs it: realtime scheduling where this user may."""
    return JackServer(realtime_priority=REALTIME_PRIORITY if realtime_allowed() else None)


@pytest.fixture
def jack():
    with performer_jack() as server:
        yield server


@pytest.fixture
def display():
    if not Xvfb.available():
        pytest.fail("Xvfb is not installed (scripts/setup.sh installs the package xvfb)")
    with Xvfb() as xvfb:
        yield xvfb
