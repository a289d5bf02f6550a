"""What every realtime test file shares: `jack`, a JACK server of its own on the dummy driver
(unique name), started for the test and stopped after it by its process; `display`, a virtual X
display of its own for the windows' tests. Where this user may
use realtime scheduling it runs as a performer's would (`jackd -R`): its and scsynth's audio
threads SCHED_FIFO, and the device's threads above them (ThreadScheduling), so that the tests'
timing holds on a busy machine (scripts/realtime-under-load.sh)."""
import pytest

from kfharness.jack import performer_jack
from kfharness.xvfb import Xvfb


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
