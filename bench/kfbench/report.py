"""bench/REPORT.md: the template's blocks (bench/REPORT.md.in) filled with this run's numbers and
tables. A section whose part has no results is left out."""
import os
import subprocess

import numpy as np

from kfharness import profile

from . import drive_path, goals, patterns, realtime, report_rate, rtload, spatial, texture_rate, thresholds, timing
from .common import BLOCK, DEVICE, FORCE_FRAME_MS, GRID_SPEEDS, LOOP_HZ, LOUDNESS_IN_SC, LTF_N, MAPPING, MAPPINGS, \
    ORIGIN, PARTS, PILOT_PERIOD, SPATIAL_S, SR, fmt, running_sum_chain_sc
from .native import reconstruction_checks
from .summary import DRIFT_TEST_RATE_HZ, key_numbers, repeatability_table, summary_lines, voices
from .template import render

CMD = "/usr/bin/python3 bench/run.py"
E2E_PERIOD = 64  # kfharness.jack's default period
AUDIO_DELAY_MS = round(profile.audio_delay_s() * 1e3, 6)


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def _scsynth_version():
    out = subprocess.run(["scsynth", "-v"], stdout=subprocess.PIPE, text=True).stdout.split()
    return out[1] if len(out) > 1 else "?"


def header(results):
    meta = results.get("meta", {})
    parts = meta.get("parts", PARTS)
    return render("header", cmd=CMD, date=meta.get("date", "?"), cores=os.cpu_count(), scsynth=_scsynth_version(),
                  parts="all parts" if set(parts) >= set(PARTS) else "parts: " + ", ".join(parts),
                  bench_min=meta.get("bench_s", 0) / 60, build_s=meta.get("build_s", 0),
                  goals="\n".join(f"- {g}" for g in goals.goals(results)), summary="\n".join(summary_lines(results)))


def provenance(results):
    """Per part: the commit, date and processor that measured it, so that a part kept from an
    earlier run (a partial run does not measure it again) says so."""
    measured = results.get("measured", {})
    latest = results.get("meta", {}).get("date")
    rows = [(part, m.get("commit", "?"), m.get("date", "?") + ("" if m.get("date") == latest else " (an earlier run)"),
             m.get("processor", "?"), m.get("core_path", "?"), m.get("machine", "?"))
            for part in results if part not in ("meta", "measured") for m in [measured.get(part, {})]]
    return [render("provenance", table=table(["part", "commit", "date", "processor", "code path", "machine"], rows))]


def repeatability(results):
    return [render("repeatability", table=repeatability_table(key_numbers(results)))]


def notes(results):
    tm, sp, ld, lc = results.get("timing"), results.get("spatial"), results.get("loudness"), results.get("log")
    if not (tm and sp and ld and lc):
        return []
    r = tm["ratios"]
    logs = {row["name"]: row for row in lc["rows"]}
    long = sp["index"][spatial.LONG_LABEL]
    ns = {k: float(np.median(v)) for k, v in tm["ns"]["cpu"].items()}
    # Timing results from before the device UGens were in the render have no such phases.
    device_ugens = render("notes_device_ugens", mousein=ns["mousein"], fout=ns["fout"]) + "\n" if "mousein" in ns else ""
    return [render("notes", ns=ns, device_ugens=device_ugens,
                   spat_cubic=r["SpatialBufRd/BufRd cubic"]["cpu-empty"]["median"],
                   spat_linear=r["SpatialBufRd/BufRd linear"]["cpu-empty"]["median"],
                   spat_none=r["SpatialBufRd/BufRd none"]["cpu-empty"]["median"],
                   ltf_chain=r["LoudnessToFriction/RunningSum chain"]["cpu-empty"]["median"],
                   spm=MAPPINGS[0], origin=ORIGIN, pilot=sp["pilot"][f"pilot {MAPPINGS[0]} samples/mm, 100 mm/s"],
                   long=long, long_wrong_percent=100 * long["BufRd none"]["wrong_sample_fraction"],
                   far=sp["index"][spatial.FAR_LABEL], far_origin=spatial.FAR_ORIGIN_MM, n=LTF_N,
                   loudness_goal=goals.LOUDNESS_GOAL, error_goal=goals.ERROR_GOAL_TEXT,
                   log_current=logs["std::log10 (double)"],
                   log_exact=logs["std::log (double) * log10(e), the exact path"], errors=ld["errors"],
                   path=tm.get("core_path", "?"))]


def timing_section(tm):
    ratios = table(["pair", "CPU ratio", "[min..max]", "wall ratio", "CPU ratio, source subtracted", "[min..max]"],
                   [(label, f"{c['median']:.3f}", f"{c['min']:.3f}..{c['max']:.3f}", f"{w['median']:.3f}",
                     f"{s['median']:.3f}", f"{s['min']:.3f}..{s['max']:.3f}")
                    for label, e in tm["ratios"].items()
                    for c, w, s in [(e["cpu-empty"], e["wall-empty"], e["cpu-source"])]])
    ns = table(["phase", "synth", "ns"], [(n, f"`{timing.DEFS[n]}`", f"{np.median(v):.2f}")
                                          for n, v in tm["ns"]["cpu"].items()])
    return render("timing", cmd=CMD, rounds=tm["rounds"], phase_s=tm["phase_s"], instances=tm["instances"],
                  settle_s=timing.SETTLE_S, tail_s=timing.TAIL_S, ratios=ratios, ns=ns)


def spatial_section(sp, tm):
    tradeoff = ""
    if tm:
        rows = []
        for n, label in timing.READERS:
            e, es = tm["vs_bufrd4"][n]["cpu-empty"], tm["vs_bufrd4"][n]["cpu-source"]
            rows.append((label, f"{e['median']:.3f}", f"{e['min']:.3f}..{e['max']:.3f}", f"{es['median']:.3f}",
                         fmt(max(en[label]["max_vs_signal"] for en in sp["pilot"].values())),
                         fmt(max(en[label]["rms_vs_signal"] for en in sp["pilot"].values()))))
        tradeoff = table(["reader", "CPU / BufRd cubic", "[min..max]", "source subtracted",
                          "max error vs signal, worst case", "rms vs signal, worst case"], rows)
    by_case = {stat: table(["mapping, speed"] + [label for _, label in timing.READERS],
                           [[f"{en['spm']} samples/mm, {en['speed']} mm/s"]
                            + [fmt(en[label][stat]) for _, label in timing.READERS] for en in sp["pilot"].values()])
               for stat in ("max_vs_signal", "rms_vs_signal", "max_vs_double_read")}
    rows = []
    for label, entry in sp["index"].items():
        for k, v in entry.items():
            if k.startswith("_") or not isinstance(v, dict):
                continue
            other = fmt(v["rms_index_error"]) if "rms_index_error" in v else f"{100 * v['wrong_sample_fraction']:.2f} %"
            rows.append((label, k, fmt(v["max_index_error"]), other))
        rows.append((label, "(the float position itself)", f"step {fmt(entry['index_step_from_position_ulp'])} samples "
                     f"(position ulp {fmt(entry['position_ulp_mm'])} mm), shared by both", ""))
    index = table(["case", "reader", "max index error", "rms / wrong-sample share"], rows)
    return render("spatial", cmd=CMD, instances=tm["instances"] if tm else "?",
                  mappings=", ".join(map(str, MAPPINGS)), speeds=", ".join(map(str, GRID_SPEEDS)), seconds=SPATIAL_S,
                  period=PILOT_PERIOD, tradeoff=tradeoff, index=index, **by_case)


def loudness_section(ld):
    rows = [(name, fmt(e["max_n"]), fmt(e["rms_n"]), fmt(e["max_n_inside_clip"])) for name, e in ld["errors"].items()]
    return render("loudness", cmd=CMD, seconds=ld["seconds"], input=LOUDNESS_IN_SC, rate_khz=SR // 1000, n=LTF_N,
                  running_sum_chain=running_sum_chain_sc("in"),
                  table=table(["chain", "max error (N)", "rms error (N)", "max inside the clip range (N)"], rows))


def drift_section(dr):
    rows = [(name, fmt(dr["first"][name]["max_n"]), fmt(dr["last"][name]["max_n"]), fmt(dr["first"][name]["rms_n"]),
             fmt(dr["last"][name]["rms_n"])) for name in dr["first"]]
    return render("drift", cmd=CMD, minutes=dr["minutes"], rate_khz=SR // 1000, capture_s=dr["capture_s"],
                  table=table(["chain", "max error first (N)", "max error last (N)", "rms first (N)", "rms last (N)"],
                              rows))


def drift_test_section(dt):
    return render("drift_test", cmd=CMD, command=dt["command"], n=round(DRIFT_TEST_RATE_HZ * MAPPING["windowS"]),
                  window_ms=MAPPING["windowS"] * 1e3, rate_khz=DRIFT_TEST_RATE_HZ // 1000, worst_n=dt["worst_n"],
                  wall_s=dt["wall_s"])


def reconstruction_section(rc, build_dir):
    accuracy = table(["movement", "mode", "lag (ms)", "RMS error (mm)", "RMS error at lag (mm)", "max step (mm)"],
                     [(r["movement"], r["mode"], f"{r['lagMs']:.3f}", f"{r['rmsErrorMm']:.5f}",
                       f"{r['rmsErrorAtLagMm']:.5f}", f"{r['maxStepMm']:.5f}") for r in rc["accuracy"]])
    cpu = table(["mode", "CPU ns/sample", "[min..max] over runs", "/ linear"],
                [(m, f"{rc['cpu'][m]:.2f}", f"{min(v):.2f}..{max(v):.2f}", f"{rc['cpu'][m] / rc['cpu']['linear']:.3f}")
                 for m, v in rc["cpu_runs"].items()])
    checks = reconstruction_checks(rc)
    movements = "; ".join(render("reconstruction_movement", rms_ratio=c["pred_rms_mm"] / c["lin_rms_mm"], **c)
                          for c in checks)
    return render("reconstruction", cmd=CMD, exe=f"{build_dir}/bench/kf_reconstruction_bench", runs=rc["runs"],
                  update_rate_hz=DEVICE["updateRateHz"], count_mm=DEVICE["countMm"], rate_khz=SR // 1000,
                  accuracy=accuracy, cpu=cpu, movements=movements,
                  status="MET" if all(c["met"] for c in checks) else "NOT MET")


def report_rate_section(rr, build_dir):
    return render("report_rate", cmd=CMD, exe=f"{build_dir}/bench/kf_report_rate_bench",
                  rate_khz=rr["sampleRateHz"] // 1000, block=rr["blockSize"], spec_rate_hz=rr["specRateHz"],
                  recordings=report_rate.recordings_table(rr, table), simulated=report_rate.simulated_table(rr, table))


def drive_section(dr):
    paths, pulses = drive_path.report_tables(dr, table)
    return render("drive", cmd=CMD, rate_khz=dr["sampleRateHz"] // 1000, block=dr["blockSize"],
                  height_n=dr["heightN"], paths=paths, pulses=pulses)


def patterns_section(pt, build_dir):
    return render("patterns", cmd=CMD, exe=f"{build_dir}/bench/kf_patterns_bench", rounds=pt["rounds"],
                  seconds=pt["seconds"], rate_khz=pt["sample_rate_hz"] // 1000, block=pt["block"],
                  fine_mm=pt["fine_mm"], angle_deg=pt["angle_deg"], loudness_ns=pt["loudness_ns"],
                  cost=patterns.cost_table(pt, table), alias=patterns.alias_table(pt, table))


def texture_rate_section(tr, build_dir):
    return render("texture_rate", cmd=CMD, exe=f"{build_dir}/bench/kf_texture_rate_bench", rounds=tr["rounds"],
                  rate_khz=tr["sample_rate_hz"] // 1000, block=tr["block"], weber=tr["weber"],
                  within_1k=tr["within_weber_hz"][0], within_8k=tr["within_weber_hz"][1],
                  within_8k_filter=tr["within_weber_hz"][2], latency_1k=tr["latency_ms"][0],
                  latency_8k=tr["latency_ms"][1], latency_8k_filter=tr["latency_ms"][2],
                  variants=texture_rate.variants_table(tr, table), fidelity=texture_rate.fidelity_table(tr, table),
                  textures=texture_rate.textures_table(tr, table), device=texture_rate.device_table(tr, table),
                  device_seconds=tr["device"]["seconds"], device_rounds=tr["device"]["rounds"], build_dir=build_dir,
                  **dict(zip(["tex_1k", "tex_8k", "tex_8k_filter"], texture_rate.textures_within_weber_hz(tr))))


def thresholds_section(th):
    procedures, fits = thresholds.tables(th, table)
    q = th["questplus_reference"]
    return render("thresholds", cmd=CMD, runs=th["runs"], obs=th["observer"], targets=th["targets"],
                  sclang_s=th["sclang_s"], procedures=procedures, fits=fits, same=q["same_choice"], trials=q["trials"],
                  max_difference=q["max_relative_difference"], replay_s=q["replay_s"], own_s=q["own_s"],
                  load_before=", ".join(f"{v:.2f}" for v in th["load_before"]),
                  load_after=", ".join(f"{v:.2f}" for v in th["load_after"]))


def e2e_section(e2e):
    runs = e2e["runs"]
    rows = [(i + 1, key, f"{r[key]['p50_ms']:.3f}", f"{r[key]['p99_ms']:.3f}", f"{r[key]['max_ms']:.3f}", r[key]["n"])
            for i, r in enumerate(runs) for key in realtime.MEASURES]
    return render("e2e", cmd=CMD, rate=SR, period=E2E_PERIOD, block=BLOCK, audio_delay_ms=AUDIO_DELAY_MS,
                  signal_mm=realtime.SIGNAL_MM, hand_mm_per_s=realtime.SIGNAL_MM / 0.5, seconds=e2e["seconds"],
                  loop_khz=LOOP_HZ / 1000, frame_ms=FORCE_FRAME_MS, runs=len(runs), block_ms=BLOCK / SR * 1e3,
                  table=table(["run", "measure", "p50 (ms)", "p99 (ms)", "max (ms)", "n"], rows),
                  overflows=", ".join(f"{r.get('overflows')}" for r in runs),
                  xruns=", ".join(f"{r['client_xruns']} / {r['driver_xruns']}" for r in runs),
                  avg_cpu=", ".join(f"{r['avg_cpu']:.1f} %" for r in runs if r.get("avg_cpu") is not None))


def rtload_section(rt):
    rows = []
    for r in rt["runs"]:
        f, m = r["force"], r["mouse"]
        rows.append((f"{r['rate'] // 1000} kHz / {r['period']}", r["condition"],
                     f"{f['forceP50S'] * 1e3:.3f}", f"{f['forceP99S'] * 1e3:.3f}", f"{f['forceP999S'] * 1e3:.3f}",
                     f"{f['forceMaxS'] * 1e3:.3f}", f"{(f['loopP99S'] - f['loopP50S']) * 1e3:.3f}",
                     f"{f['loopMaxS'] * 1e3:.3f}", f"{f['missedDeadlines']:.0f}",
                     f"{f['skippedFrames'] + f['frameQueueOverflows']:.0f}", f"{f['watchdogTrips']:.0f}",
                     f"{m['reportP99S'] * 1e3:.3f}", f"{m['reportMaxS'] * 1e3:.3f}",
                     f"{f['deviceThreadPriority']:.0f} / {m['mouseThreadPriority']:.0f}",
                     f"{r['client_xruns']}", faults(r),
                     rtload.machine_ms(r, "p99_us"), rtload.machine_ms(r, "max_us")))
    return render("rtload", cmd=CMD, seconds=rt["seconds"], load=rt["load"], priority=rt["jack_priority"],
                  table=table(["rate / period", "scheduling", "force p50 (ms)", "p99", "p99.9", "max",
                               "loop jitter p99 (ms)", "loop max (ms)", "missed deadlines", "missed frames",
                               "watchdog trips", "report to UGen p99 (ms)", "max", "device / reader thread",
                               "JACK xruns", "device threads' page faults (minor / major)",
                               "machine wake-up p99 (ms)", "max"], rows))


def faults(run):
    """The two device threads' page faults during the run, "-" where not counted (older results)."""
    counts = [run.get("faults", {}).get(name) for name in ("kf-device-0", "kf-device-1")]
    return "-" if None in counts else " + ".join(f"{minor} / {major}" for minor, major in counts)


def scale_section(sc):
    rates = []
    for rate, e in sc.items():
        searches = [e] + ([e["tolerant"]] if e.get("tolerant") else [])
        rows = [(f"{100 * x['xrun_fraction']:g} %", r["voices"], ", ".join(map(str, r["window_xruns"])),
                 r["driver_xruns"], f"{r['avg_cpu']:.1f}", f"{r['peak_cpu']:.1f}")
                for x in searches for r in x["steps"]]
        tol = e.get("tolerant") or {}
        rates.append(render("scale_rate", rate_khz=int(rate) // 1000,
                            voices=voices(e.get("in_every_search", e["max_without_xrun"])),
                            searches=len(e.get("all_runs", [0])), all_runs=", ".join(map(str, e.get("all_runs", []))),
                            reversals=", ".join(map(str, e.get("all_reversals", []))),
                            confirmed="each confirmed by its re-tests" if e.get("all_confirmed")
                            else "NOT all confirmed: a search ran out of time before its re-tests agreed",
                            first_failing=e["first_with_xrun"], wall_s=e["wall_s"],
                            tolerant=voices(tol.get("max_without_xrun", -1)),
                            tolerant_percent=100 * tol.get("xrun_fraction", 0), tolerant_limit=tol.get("xrun_limit", 0),
                            tolerant_reversals=tol.get("reversals", 0),
                            table=table(["allowed misses", "voices", "xruns per window", "dummy driver late",
                                         "avg CPU %", "peak CPU %"], rows)))
    first = next(iter(sc.values()))
    return render("scale", cmd=CMD, mappings=", ".join(map(str, MAPPINGS)), audio_delay_ms=AUDIO_DELAY_MS,
                  priority=realtime.REALTIME_PRIORITY, period=E2E_PERIOD, settle_s=first["settle_s"],
                  window_s=first["window_s"], repeats=first.get("repeats", 1), rates="\n\n".join(rates))


def log_section(lc, build_dir):
    rows = [(r["name"], f"{r['map_ns']:.2f}", f"{r['core_ns']:.2f}", fmt(r["worst_n"]), fmt(r["rms_n"]))
            if "worst_n" in r else (f"{r['name']} (the real core)", "", f"{r['core_ns']:.2f}", "", "")
            for r in lc["rows"]]
    return render("log", cmd=CMD, exe=f"{build_dir}/bench/kf_log_choice",
                  table=table(["logarithm", "mapping ns", "core ns/sample", "worst error (N)", "rms error (N)"], rows))


def write(results, path, build_dir="build"):
    sections = [header(results)] + provenance(results) + repeatability(results) + notes(results)
    get = results.get
    for key, make in (("timing", lambda: timing_section(get("timing"))),
                      ("spatial", lambda: spatial_section(get("spatial"), get("timing"))),
                      ("loudness", lambda: loudness_section(get("loudness"))),
                      ("drift", lambda: drift_section(get("drift"))),
                      ("drift_test", lambda: drift_test_section(get("drift_test"))),
                      ("reconstruction", lambda: reconstruction_section(get("reconstruction"), build_dir)),
                      ("report_rate", lambda: report_rate_section(get("report_rate"), build_dir)),
                      ("drive", lambda: drive_section(get("drive"))),
                      ("patterns", lambda: patterns_section(get("patterns"), build_dir)),
                      ("texture_rate", lambda: texture_rate_section(get("texture_rate"), build_dir)),
                      ("thresholds", lambda: thresholds_section(get("thresholds"))),
                      ("e2e", lambda: e2e_section(get("e2e"))),
                      ("rtload", lambda: rtload_section(get("rtload"))),
                      ("scale", lambda: scale_section(get("scale"))),
                      ("log", lambda: log_section(get("log"), build_dir))):
        if get(key):
            sections.append(make())
    path.write_text("\n\n".join(sections) + "\n")
