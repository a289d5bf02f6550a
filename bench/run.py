#!/usr/bin/python3
"""KineticFriction speed-against-error benchmarks: builds what it needs, runs everything, prints
the ratios with their errors and the goals, and writes bench/REPORT.md (prose from
bench/REPORT.md.in), bench/results.json and PNG plots into bench/. The parts live in
bench/kfbench/; the harness (sclang, scsynth renders, JACK) is python/kfharness, so PYTHONPATH
must hold python/ (scripts/env.sh sets it).

    scripts/bench.sh                              # scripts/setup.sh (install, build), then this
    /usr/bin/python3 bench/run.py                 # everything (about 7 minutes on 2 cores, build excluded)
    /usr/bin/python3 bench/run.py --only timing   # one part (repeatable): build, log, timing, spatial,
                                                  # loudness, drift, reconstruction, report_rate, e2e,
                                                  # rtload, scale, drive, patterns

Parts:
  log       bench/log_choice.cpp: the logarithm of equation (2), std::log10 against faster ones
  timing    one scsynth NRT render: phases of many instances of SpatialBufRd / BufRd (cubic,
            linear, none) and LoudnessToFriction / RunningSum chain / Amplitude chain, timed by
            the KFBenchClock UGen (wall and thread CPU time per block, written to the file)
  spatial   error of SpatialBufRd and BufRd against the exact signal and the exact index
  loudness  error of the three loudness-to-force chains against equations (1) and (2) in double
  drift     the same error after a long render (default 20 minutes of audio), and the Catch2 test
            `no drift: 10^9 samples ...` of build/tests/dsp_tests (the core alone, 10^9 samples)
  reconstruction  build/bench/kf_reconstruction_bench: FrictionMouseIn's modes (hold, linear,
            predictive) against the simulated puck's true trajectory: lag, RMS error, CPU
  report_rate  build/bench/kf_report_rate_bench: the synthetic recordings of tests/data/hid (125 Hz
            8-bit, 1 kHz 12-bit, 8 kHz 16-bit, one known trajectory) replayed through FrictionMouseIn's
            modes against that trajectory (position error, lag, saturated reports), and the
            simulated mouse at 125 Hz .. 8 kHz
  e2e       realtime: scsynth on `jackd -d dummy` (48 kHz, period 64), a FrictionPilot on
            FrictionDevice.sim for 10 s (three times), then kfStatus: loop period, report-to-UGen
            and force-to-magnet latencies
  rtload    realtime: force and report latencies, loop jitter, missed deadlines and watchdog
            trips with realtime scheduling, with it under load (2 CPU hogs, a disk writer) and at
            normal priority under load, at 48 kHz / 64 and 256 and 192 kHz / 256 (20 s each)
  scale     realtime: voices of the pilot chain on one simulated device, added stepwise until
            scsynth misses periods, at 48 and 192 kHz
  patterns  build/bench/kf_patterns_bench: every FrictionPattern kind at 5 and 300 mm/s over a
            0.2 mm pattern, ns/sample with anti-aliasing on and off (and beside LoudnessToFriction),
            and the largest alias in the 1 ms frames at 300 mm/s with it on and off
"""
import argparse

from kfbench.common import PARTS, point_harness_at
from kfharness import paths


def arguments():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", action="append", choices=PARTS, help="run only these parts (repeatable)")
    ap.add_argument("--build-dir", default=str(paths.REPO_DIR / "build"),
                    help="default: build/, as scripts/setup.sh makes it")
    ap.add_argument("--work-dir", default=None, help="scratch folder (default: a new one under /tmp)")
    ap.add_argument("--instances", type=int, default=400)
    ap.add_argument("--phase-s", type=float, default=1.5)
    ap.add_argument("--rounds", type=int, default=20)
    ap.add_argument("--drift-min", type=float, default=20)
    ap.add_argument("--e2e-s", type=float, default=10.0, help="seconds of each realtime end-to-end run")
    ap.add_argument("--e2e-runs", type=int, default=3)
    ap.add_argument("--rtload-s", type=float, default=20.0, help="seconds of each run of the rtload part")
    ap.add_argument("--scale-runs", type=int, default=3, help="scale searches per sample rate")
    ap.add_argument("--core-path", choices=["auto", "portable"], default=None,
                    help="the cores' code path for everything the run starts: portable sets KF_CORE_PATH=portable "
                         "(default: the environment's KF_CORE_PATH, else avx2 where the processor has it)")
    ap.add_argument("--no-report", action="store_true", help="print only; leave bench/REPORT.md and the plots alone")
    ap.add_argument("--report-only", action="store_true",
                    help="measure nothing: rewrite bench/REPORT.md from bench/results.json")
    return ap.parse_args()


if __name__ == "__main__":
    args = arguments()
    point_harness_at(args.build_dir, args.work_dir)  # before kfharness is asked for a folder
    from kfbench import runner
    runner.main(args)
