"""The targets the bench runs, in the build folder scripts/setup.sh makes (configured the same way
if it is not there yet), and the extension folder the renders and realtime parts load."""
import subprocess

from kfharness import paths

from .common import log


def needed(bench):
    """True when a bench target is missing (then the build part runs even if not asked for)."""
    return not (bench.exe("bench", "KFBenchClock.so").exists()
                and bench.exe("bench", "kf_reconstruction_bench").exists()
                and bench.exe("bench", "kf_report_rate_bench").exists()
                and bench.exe("bench", "kf_core_path").exists()
                and bench.exe("bench", "kf_patterns_bench").exists()
                and bench.exe("bench", "kf_texture_rate_bench").exists()
                and bench.exe("bench", "kf_device_rate_bench").exists())


def build(bench):
    if not (bench.build / "CMakeCache.txt").exists():
        log(f"configuring {bench.build} (as scripts/setup.sh does)")
        subprocess.run(["cmake", "-S", str(paths.REPO_DIR), "-B", str(bench.build), "-DCMAKE_BUILD_TYPE=Release"],
                       check=True, stdout=subprocess.DEVNULL)
    targets = ["KineticFriction", "KFBenchClock", "kf_log_choice", "kf_reconstruction_bench", "kf_report_rate_bench",
               "kf_core_path", "kf_patterns_bench", "kf_texture_rate_bench", "kf_device_rate_bench"]
    if bench.tests_enabled():
        targets.append("dsp_tests")
    log(f"building {', '.join(targets)} (-j2)")
    for cmd, what in ((["cmake", "--build", str(bench.build), "-j2", "--target", *targets], "build"),
                      (["cmake", "--install", str(bench.build)], "cmake --install")):
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if proc.returncode != 0:
            print(proc.stdout[-4000:])
            raise SystemExit(f"{what} failed")
