"""The magnet goes off however scsynth leaves. A simulated device in realtime gets a
constant 1.4 N (the maximum) from FrictionOut while kfRecord writes a kf-session file; then
scsynth is stopped by a signal. Its handler (host/ExitSafetyPosix.cpp) must drive the force
backend off and append the off record before the process ends: the recording ends with an
`O` line after the 1.4 N frames. Without the handler the last commanded force stays 1.4 N.
The crash signals are sent too (as a crashing server would raise them), with core files off.
"""
import os
import resource
import signal

import pytest

from conftest import performer_jack
from kfharness import paths, procs, sclang
from kfstudy import readers

FORCE_N = 1.4
# Frames the device applies before the signal (the script waits for them), and the fewest the
# recording must hold: the frames the recording's writer had not written yet are lost with the
# process (it writes every 10 ms at normal priority: the off record came at most 0.019 s after
# the last frame written, measured under load), so half of them is a margin of 0.3 s.
FRAMES = 600


def signal_each_in_turn(jack, signal_numbers, records):
    """One sclang run: for each signal in turn, boots scsynth (the run's first boot is the
    harness's), drives 1.4 N into device 0 while recording to records[signal], sends the signal
    to scsynth and waits until it is gone. Posts "KF-GONE <signal> <seconds waited> <pid>" for
    each, or "KF-SIGNAL-ERROR <signal>" when its turn failed; either way the turn ends with the
    server gone and no device held, so the next signal starts as on a fresh server: sclang's
    FrictionDevice would otherwise open the old device again at the boot (prServerBoot)."""
    for record in records.values():
        record.unlink(missing_ok=True)
    turns = ", ".join(f"[{int(n)}, {sclang.sc_string(records[n])}]" for n in signal_numbers)
    return sclang.run_with_server(f"""
        var period = s.aliveThreadPeriod;
        [{turns}].do {{ |turn, i|
            var signal = turn[0], record = turn[1], dev, pid, waited = 0, seen = 0, applied = 0, polls = 0;
            try {{
                if(i > 0) {{
                    // As the harness boots (sclang.py): polled every 0.05 s while booting.
                    s.aliveThreadPeriod = 0.05;
                    s.bootSync;
                    s.aliveThreadPeriod = period;
                }};
                SynthDef(\\kfPush, {{ FrictionOut.ar(0, DC.ar({FORCE_N})) }}).add;
                dev = FrictionDevice.sim(s, 0);
                s.sync;
                dev.record(record);
                s.sync;
                Synth(\\kfPush);
                s.sync;
                // Until the device has applied {FRAMES} frames of 1.4 N ({FRAMES} ms of the server's
                // audio), not for a time of sclang's clock: without realtime scheduling the server
                // lost audio cycles, and 0.6 s of the clock held as little as 0.15 s of audio.
                while {{ applied < {FRAMES} and: {{ polls < 200 }} }} {{
                    var answered = Condition.new;
                    dev.statusValues {{ |values| applied = values[\\frames]; answered.test = true; answered.signal }};
                    answered.wait;
                    0.05.wait; polls = polls + 1;
                }};
                pid = s.pid;
                ("kill -" ++ signal ++ " " ++ pid).unixCmd;
                // Until the process is gone (kill -0 fails), at most 10 s.
                while {{ waited < 10 and: {{ ("kill -0 " ++ pid ++ " 2>/dev/null").systemCmd == 0 }} }} {{
                    0.1.wait; waited = waited + 0.1;
                }};
                "KF-GONE % % %\n".postf(signal, waited, pid);
            }} {{ |error|
                error.reportError;
                "KF-SIGNAL-ERROR %\n".postf(signal);
            }};
            // The turn's server goes (SIGKILL if the signal did not end it) and sclang sees it
            // go (Server.prOnServerProcessExit), then forgets its devices: nothing is sent.
            s.pid !? {{ |left| if(("kill -0 " ++ left ++ " 2>/dev/null").systemCmd == 0) {{ ("kill -9 " ++ left).systemCmd }} }};
            while {{ (s.pid.notNil or: {{ s.serverRunning }}) and: {{ seen < 10 }} }} {{ 0.05.wait; seen = seen + 0.05 }};
            FrictionDevice.all.do(_.close);
        }};
    """, jack, name="signals", timeout=60 + 20 * len(signal_numbers))


# Every signal whose default action ends the process (signal(7)); SIGXFSZ, which the plugin
# ignores, is test_file_size_limit's, and scsynth ignores SIGPIPE itself (a signal ignored when
# the plugin loads stays ignored: it ends nothing; tests/host/test_exit_hook covers it).
SIGNALS = [signal.SIGTERM, signal.SIGINT, signal.SIGHUP, signal.SIGQUIT, signal.SIGUSR1, signal.SIGUSR2,
           signal.SIGALRM, signal.SIGVTALRM, signal.SIGPROF, signal.SIGXCPU, signal.SIGPWR,
           signal.SIGSTKFLT, signal.SIGABRT, signal.SIGSYS, signal.SIGTRAP, signal.SIGSEGV, signal.SIGBUS,
           signal.SIGFPE, signal.SIGILL]


# The handler hands these on to AddressSanitizer's, which reports them as a finding.
CAUGHT_BY_ASAN = (signal.SIGSEGV, signal.SIGBUS, signal.SIGFPE)


def sanitized():
    return bool(os.environ.get("KF_SERVER_PRELOAD"))


@pytest.fixture(scope="module")
def signalled():
    """Every signal's turn, in one sclang run (a server per signal, booted in turn), with core
    files off: the crash signals' default action dumps core, not from these servers (the limit
    is inherited by sclang and the scsynths it starts). Returns the run and the recordings."""
    sent = [n for n in SIGNALS if not (sanitized() and n in CAUGHT_BY_ASAN)]
    records = {n: paths.work_dir() / f"signal-{int(n)}.txt" for n in sent}
    previous = resource.getrlimit(resource.RLIMIT_CORE)
    resource.setrlimit(resource.RLIMIT_CORE, (0, previous[1]))
    try:
        with performer_jack() as jack:
            return signal_each_in_turn(jack, sent, records), records
    finally:
        resource.setrlimit(resource.RLIMIT_CORE, previous)


@pytest.mark.parametrize("signal_number", SIGNALS, ids=[s.name for s in SIGNALS])
def test_a_signal_drives_the_magnet_off(signalled, signal_number):
    if sanitized() and signal_number in CAUGHT_BY_ASAN:
        pytest.skip("AddressSanitizer's handler, which ours hands the signal on to, reports it as a finding")
    run, records = signalled
    record = records[signal_number]
    assert [str(int(signal_number))] not in run.lines("KF-SIGNAL-ERROR "), f"its turn failed:\n{run.output[-4000:]}"
    gone = [fields[1:] for fields in run.lines("KF-GONE ") if fields[0] == str(int(signal_number))]
    assert gone, f"no turn for {signal_number.name} (the run ended before it):\n{run.output[-4000:]}"
    assert float(gone[0][0]) < 10, f"scsynth did not end on the signal:\n{run.output[-4000:]}"
    assert procs.wait_pid_gone(int(gone[0][1]), 5)

    header, records = readers.read_session(record)
    frames = [fields for tag, fields in records if tag == "F"]
    assert len(frames) >= FRAMES // 2, f"only {len(frames)} frames recorded before the signal"
    # The magnet was at the maximum until the signal...
    assert frames[-1][3] == pytest.approx(FORCE_N, abs=1e-6), frames[-1]
    # ... and the last record is the handler's: magnet off, after the last frame.
    tag, fields = records[-1]
    assert tag == "O", f"the recording ends with {records[-3:]}, not an off record"
    assert fields[0] >= frames[-1][0] - 1e-3
    print(f"{signal.Signals(signal_number).name}: off {(fields[0] - frames[-1][0]) * 1e3:.3f} ms after the last frame")
    assert float(header["minForceN"]) == pytest.approx(0.14)
