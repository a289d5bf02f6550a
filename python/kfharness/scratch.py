"""A pytest plugin (-p kfharness.scratch: every pytest ctest runs with it, tests/CMakeLists.txt):
a test file's scratch folder (paths.work_dir, a new one in /tmp per process) is removed once all
its tests have passed, and kept, its path posted, when one failed, for its logs and renders.
Kept whole, one ctest stage left 102 of them, 669 MB, in /tmp. KF_TEST_WORK_DIR names a folder
of one's own: it is left as it is."""
import os
import shutil

from . import paths, sclang_session


def pytest_sessionfinish(session, exitstatus):
    sclang_session.stop_shared()  # it runs in the scratch folder
    if os.environ.get("KF_TEST_WORK_DIR") or paths.work_dir.cache_info().currsize == 0:
        return  # a folder of one's own, or none made
    if exitstatus == 0:
        shutil.rmtree(paths.work_dir(), ignore_errors=True)
    else:
        print(f"\nscratch folder kept: {paths.work_dir()}")
