"""A process's scratch folder (paths.work_dir, a new one in /tmp per process) removed once its
work passed, and kept, its path posted, when it failed, for its logs and renders. Kept whole, one
ctest stage left 102 of them, 669 MB, in /tmp, and each run of the main job one of 113 MB.
KF_TEST_WORK_DIR names a folder of one's own: it is left as it is.

Two ways in: a pytest plugin (-p kfharness.scratch: every pytest ctest runs with it,
tests/CMakeLists.txt), and `with scratch.for_job():` around a job script's main (scripts/main.sh,
study.sh, gallery.sh). A test that runs a job finds the job's folder with job_environment and
job_folders."""
import contextlib
import os
import shutil

from . import paths, sclang_session


def finish(passed):
    """Stops the shared sclang (it runs in the folder), then removes the folder or posts where it is kept."""
    sclang_session.stop_shared()
    if os.environ.get("KF_TEST_WORK_DIR") or paths.work_dir.cache_info().currsize == 0:
        return  # a folder of one's own, or none made
    if passed:
        shutil.rmtree(paths.work_dir(), ignore_errors=True)
    else:
        print(f"\nscratch folder kept: {paths.work_dir()}", flush=True)


def pytest_sessionfinish(session, exitstatus):
    finish(exitstatus == 0)


@contextlib.contextmanager
def for_job():
    """The job's work: passed when it returns, failed when it raises (SystemExit included: a job
    exits with a code only to fail, or on Ctrl-C or SIGTERM, procs.finish_on_sigterm)."""
    passed = False
    try:
        yield
        passed = True
    finally:
        finish(passed)


def job_environment(parent):
    """The environment for a job a test runs, whose scratch folder it is to find in `parent`: the
    test's own environment, with tempfile's folder moved there and no KF_TEST_WORK_DIR."""
    env = {**os.environ, "TMPDIR": str(parent)}
    env.pop("KF_TEST_WORK_DIR", None)
    return env


def job_folders(parent):
    """The scratch folders jobs run with job_environment(parent) left."""
    return sorted(parent.glob(paths.WORK_DIR_PREFIX + "*"))
