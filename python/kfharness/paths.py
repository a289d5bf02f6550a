"""Where things are. Every location can be moved by an environment variable, read when asked."""
import functools
import os
import tempfile
from pathlib import Path

REPO_DIR = Path(__file__).resolve().parents[2]
SYSTEM_PLUGIN_DIR = Path("/usr/lib/SuperCollider/plugins")


def extension_dir():
    """The installed extension folder (plugin, classes, help): KF_EXTENSION_DIR or build/'s."""
    return Path(os.environ.get("KF_EXTENSION_DIR") or REPO_DIR / "build" / "KineticFriction")


def test_data_dir():
    """Recorded device data in the repository (tests/data), or KF_TEST_DATA_DIR."""
    return Path(os.environ.get("KF_TEST_DATA_DIR") or REPO_DIR / "tests" / "data")


WORK_DIR_PREFIX = "kf-work-"


@functools.lru_cache(maxsize=None)
def work_dir():
    """A scratch folder for scripts, renders and logs, made on first use: KF_TEST_WORK_DIR or a
    new temporary folder (one per process)."""
    path = Path(os.environ.get("KF_TEST_WORK_DIR") or tempfile.mkdtemp(prefix=WORK_DIR_PREFIX))
    path.mkdir(parents=True, exist_ok=True)
    return path
