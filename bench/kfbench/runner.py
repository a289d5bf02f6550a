"""The parts in order: build, log, the NRT renders (timing, spatial, loudness, drift), the drift
test, reconstruction, the realtime parts; then the summary, the goals, results.json (the parts not
run this time kept as they were, each with the commit and date that measured it), the report and
the plots."""
import json
import os
import time

from kfharness import nrt

from . import build, drift, drive_path, goals, loudness, native, patterns, plots, provenance, realtime, report, report_rate, \
    texture_rate, \
    rtload, scores, spatial, thresholds, timing
from .common import BENCH_DIR, PARTS, T0, Bench, fmt, log
from .summary import summary_lines

RESULTS_PATH = BENCH_DIR / "results.json"
REPORT_PATH = BENCH_DIR / "REPORT.md"


def _print(results):
    for line in summary_lines(results):
        print(line)


def _render(bench, name, channels, **kwargs):
    """An NRT render of the score <name>.osc into <name>.wav with the bench's UGen; its wall time."""
    return nrt.timed_render(bench.work / f"{name}.osc", bench.work / f"{name}.wav", channels=channels, timeout=900,
                            memory_kb=262144, extra_args=["-a", 1024, "-w", 1024], plugin_dirs=bench.plugin_dirs,
                            **kwargs)


def run_nrt(bench, args, parts, results):
    """One sclang run writes the scores of the NRT parts asked for; then each is rendered and analysed."""
    order = timing.schedule(args.rounds)
    spatial.write_buffers(bench)
    pieces = []
    if "timing" in parts:
        pieces.append(timing.score_code(bench, order, args.instances, args.phase_s))
    if "spatial" in parts:
        spatial.write_long_buffer(bench)
        pieces.append(spatial.score_code(bench))
    if "loudness" in parts:
        pieces.append(loudness.score_code(bench))
    if "drift" in parts:
        pieces.append(drift.score_code(bench, args.drift_min))
    log("sclang: writing the scores")
    scores.write(bench, pieces)
    report_plots = not args.no_report
    if "timing" in parts:
        log(f"timing render: {len(order)} phases ({timing.render_seconds(order, args.phase_s):.0f} s of audio, "
            f"{args.instances} instances per phase)")
        log(f"timing render took {_render(bench, 'timing', 4):.1f} s")
        results["timing"] = timing.analyse(bench, order, args.instances, args.phase_s)
        # The code path scsynth's cores took (it runs in this environment) and the processor.
        results["timing"].update(core_path=native.core_path(bench)["path"], processor=provenance.processor())
        _print({"timing": results["timing"]})
        if report_plots:
            plots.plot_timing(results["timing"], BENCH_DIR / "timing.png")
    if "spatial" in parts:
        log("spatial accuracy render")
        _render(bench, "spatial", spatial.CHANNELS)
        results["spatial"] = spatial.analyse(bench)
        _print({"spatial": results["spatial"]})
        if report_plots:
            plots.plot_spatial(results["spatial"], BENCH_DIR / "spatial_index.png")
    if "loudness" in parts:
        log("loudness accuracy render")
        _render(bench, "loudness", 5)
        results["loudness"], data, want = loudness.analyse(bench)
        _print({"loudness": results["loudness"]})
        if report_plots:
            plots.plot_loudness(data, want, BENCH_DIR / "loudness.png")
    if "drift" in parts:
        log(f"drift render: {args.drift_min} min of audio")
        wall = _render(bench, "drift", 1, sample_format="int16")
        (bench.work / "drift.wav").unlink()
        log(f"drift render took {wall:.1f} s")
        results["drift"] = drift.analyse(bench, args.drift_min)
        _print({"drift": results["drift"]})


def run_parts(bench, args, parts):
    results = {}
    if "log" in parts:
        log("log choice microbenchmark")
        results["log"] = native.run_log_choice(bench)
        print(results["log"]["stdout"], end="")
    if any(p in parts for p in ("timing", "spatial", "loudness", "drift")):
        run_nrt(bench, args, parts, results)
    if "drift" in parts:
        log("drift test: 10^9 samples through the LoudnessToFriction core (Catch2)")
        dt = drift.run_test(bench)
        if dt:
            results["drift_test"] = dt
            log(f"drift test: worst {fmt(dt['worst_n'])} N ({dt['wall_s']:.1f} s)")
    if "reconstruction" in parts:
        log("reconstruction bench (3 runs)")
        results["reconstruction"] = native.run_reconstruction(bench)
        _print({"reconstruction": results["reconstruction"]})
    if "report_rate" in parts:
        log("report-rate bench: the synthetic recordings and the simulated mouse, 125 Hz .. 8 kHz")
        results["report_rate"] = report_rate.run(bench)
        _print({"report_rate": results["report_rate"]})
    if ("e2e" in parts or "rtload" in parts or "scale" in parts) and not (bench.extension / "plugins").exists():
        raise SystemExit(f"no extension folder at {bench.extension}: run scripts/setup.sh (or --only build)")
    if "drive" in parts:
        log("drive: the audio drive's force path beside the board's frames (NRT)")
        results["drive"] = drive_path.run(bench)
        _print({"drive": results["drive"]})
    if "patterns" in parts:
        log("patterns: FrictionPattern's kinds, ns/sample with anti-aliasing on and off, and the alias it removes")
        results["patterns"] = patterns.run(bench)
        _print({"patterns": results["patterns"]})
    if "texture_rate" in parts:
        log("texture_rate: a grating's force through the framing and the board at 1 and 8 kHz, against the ideal")
        results["texture_rate"] = texture_rate.run(bench)
        _print({"texture_rate": results["texture_rate"]})
    if "thresholds" in parts:
        log(f"thresholds: the procedures against a model observer, {thresholds.RUNS} runs each, beside "
            "python3-questplus and psignifit")
        results["thresholds"] = thresholds.run(bench)
        _print({"thresholds": results["thresholds"]})
    if "e2e" in parts:
        runs = []
        for i in range(args.e2e_runs):
            log(f"realtime end to end, run {i + 1} of {args.e2e_runs} ({args.e2e_s:.0f} s)")
            runs.append(realtime.run_e2e(bench, seconds=args.e2e_s))
        results["e2e"] = {"runs": runs, "seconds": args.e2e_s}
    if "rtload" in parts:
        results["rtload"] = rtload.run_all(bench, seconds=args.rtload_s)
    if "scale" in parts:
        results["scale"] = {str(rate): realtime.run_scale_searches(bench, rate, args.scale_runs)
                            for rate in (48000, 192000)}
    return results


def write_plots(results):
    for key, plot, name in (("log", plots.plot_log_choice, "log_choice.png"),
                            ("reconstruction", plots.plot_reconstruction, "reconstruction.png"),
                            ("e2e", plots.plot_e2e, "e2e.png"), ("scale", plots.plot_scale, "scale.png")):
        if key in results:
            plot(results[key], BENCH_DIR / name)
    if "thresholds" in results:
        thresholds.plot(results["thresholds"], BENCH_DIR / "thresholds.png")
    if "timing" in results and "spatial" in results:
        plots.plot_spatial_tradeoff(results["timing"], results["spatial"], BENCH_DIR / "spatial_tradeoff.png")


def merge_with_previous(results, stamp):
    """Parts not run this time keep their numbers and their own provenance (results["measured"]:
    per part the commit, date, machine and processor that measured it)."""
    old = json.loads(RESULTS_PATH.read_text()) if RESULTS_PATH.exists() else {}
    old.pop("previous", None)  # written by older versions of the bench
    measured = {part: stamp for part in results if part != "meta"}
    merged = {**old, **results, "measured": {**old.get("measured", {}), **measured}}
    for v in merged.get("spatial", {}).get("index", {}).values():
        v.pop("_traces", None)
    return merged


def main(args):
    parts = args.only or PARTS
    if args.core_path == "portable":  # inherited by scsynth and the native benches
        os.environ["KF_CORE_PATH"] = "portable"
    elif args.core_path == "auto":
        os.environ.pop("KF_CORE_PATH", None)
    bench = Bench(args.build_dir)
    if args.report_only:
        report.write(json.loads(RESULTS_PATH.read_text()), REPORT_PATH, bench.relative(bench.build))
        log("rewrote bench/REPORT.md from bench/results.json")
        return
    log(f"work dir {bench.work}")
    if "build" in parts or build.needed(bench):
        build.build(bench)
    build_s = time.monotonic() - T0
    bench_t0 = time.monotonic()
    results = run_parts(bench, args, parts)
    results["meta"] = {"date": time.strftime("%Y-%m-%d %H:%M"), "build_s": build_s,
                       "bench_s": time.monotonic() - bench_t0, "parts": parts}
    print("\n==== summary")
    _print(results)
    print("==== goals")
    for line in goals.goals(results):
        print(line)
    log(f"bench took {results['meta']['bench_s'] / 60:.1f} min after {build_s:.0f} s of building")
    if not args.no_report:
        write_plots(results)
        merged = merge_with_previous(results, provenance.stamp(results['meta']['date'],
                                                               native.core_path(bench)["path"]))
        RESULTS_PATH.write_text(json.dumps(merged, indent=1, default=float))
        report.write(merged, REPORT_PATH, bench.relative(bench.build))
        log(f"wrote {REPORT_PATH} and {RESULTS_PATH}")
    log("done")
