"""The magnet goes off however scsynth leaves. A simulated device in realtime gets a
constant 1.4 N (the maximum) from FrictionOut while kfRecord writes a kf-session file; then
scsynth is stopped by a signal. Its handler (host/ExitSafety.cpp) must drive the force
backend off and append the off record before the process ends: the recording ends with an
`O` line after the 1.4 N frames. Without the handler the last commanded force stays 1.4 N.
The crash signals are sent too (as a crashing server would raise them), with core files off.
"""
import os
import resource
import signal

import pytest

from kfharness import paths, procs, readers, sclang

FORCE_N = 1.4


def run_and_signal(jack, signal_number, record):
    """Boots scsynth, drives 1.4 N into device 0 while recording, sends the signal to scsynth
    from sclang, and returns the sclang run once scsynth is gone."""
    record.unlink(missing_ok=True)
    return sclang.run_with_server(f"""
        var dev, synth, pid, waited = 0;
        SynthDef(\\kfPush, {{ FrictionOut.ar(0, DC.ar({FORCE_N})) }}).add;
        dev = FrictionDevice.sim(s, 0);
        s.sync;
        dev.record({sclang.sc_string(record)});
        s.sync;
        synth = Synth(\\kfPush);
        s.sync;
        0.6.wait;
        pid = s.pid;
        "KF-SIGNAL %".format(pid).postln;
        ("kill -{signal_number} " ++ pid).unixCmd;
        // Until the process is gone (kill -0 fails), at most 10 s.
        while {{ waited < 10 and: {{ ("kill -0 " ++ pid ++ " 2>/dev/null").systemCmd == 0 }} }} {{
            0.1.wait; waited = waited + 0.1;
        }};
        "KF-GONE %".format(waited).postln;
    """, jack, name=f"signal{signal_number}", timeout=90)


# Every signal whose default action ends the process (signal(7)); SIGXFSZ, which the plugin
# ignores, is test_file_size_limit's, and scsynth ignores SIGPIPE itself (a signal ignored when
# the plugin loads stays ignored: it ends nothing; tests/host/test_exit_hook covers it).
SIGNALS = [signal.SIGTERM, signal.SIGINT, signal.SIGHUP, signal.SIGQUIT, signal.SIGUSR1, signal.SIGUSR2,
           signal.SIGALRM, signal.SIGVTALRM, signal.SIGPROF, signal.SIGXCPU, signal.SIGPWR,
           signal.SIGSTKFLT, signal.SIGABRT, signal.SIGSYS, signal.SIGTRAP, signal.SIGSEGV, signal.SIGBUS,
           signal.SIGFPE, signal.SIGILL]


@pytest.fixture
def no_core_files():
    """The crash signals' default action dumps core: not from these servers (the limit is inherited
    by sclang and the scsynth it starts)."""
    previous = resource.getrlimit(resource.RLIMIT_CORE)
    resource.setrlimit(resource.RLIMIT_CORE, (0, previous[1]))
    yield
    resource.setrlimit(resource.RLIMIT_CORE, previous)


@pytest.mark.parametrize("signal_number", SIGNALS, ids=[s.name for s in SIGNALS])
def test_a_signal_drives_the_magnet_off(jack, no_core_files, signal_number):
    if os.environ.get("KF_SERVER_PRELOAD") and signal_number in (signal.SIGSEGV, signal.SIGBUS, signal.SIGFPE):
        pytest.skip("AddressSanitizer's handler, which ours hands the signal on to, reports it as a finding")
    record = paths.work_dir() / f"signal-{int(signal_number)}.txt"
    run = run_and_signal(jack, int(signal_number), record)
    gone = run.lines("KF-GONE ")
    assert gone and float(gone[0][0]) < 10, f"scsynth did not end on the signal:\n{run.output[-4000:]}"
    assert run.scsynth_pid is None or procs.wait_pid_gone(run.scsynth_pid, 5)

    header, records = readers.read_session(record)
    frames = [fields for tag, fields in records if tag == "F"]
    assert len(frames) >= 300, f"only {len(frames)} frames recorded before the signal"
    # The magnet was at the maximum until the signal...
    assert frames[-1][3] == pytest.approx(FORCE_N, abs=1e-6), frames[-1]
    # ... and the last record is the handler's: magnet off, after the last frame.
    tag, fields = records[-1]
    assert tag == "O", f"the recording ends with {records[-3:]}, not an off record"
    assert fields[0] >= frames[-1][0] - 1e-3
    print(f"{signal.Signals(signal_number).name}: off {(fields[0] - frames[-1][0]) * 1e3:.3f} ms after the last frame")
    assert float(header["minForceN"]) == pytest.approx(0.14)
