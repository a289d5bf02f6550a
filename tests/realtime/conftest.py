"""What every realtime test file shares: `jack`, a JACK server of its own on the dummy driver
(unique name), started for the test and stopped after it by its process."""
import pytest

from kfharness.jack import JackServer


@pytest.fixture
def jack():
    with JackServer() as server:
        yield server
