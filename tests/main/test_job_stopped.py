"""A main job stopped by SIGTERM (kill, timeout, a session manager) stops what it started, as one
stopped with Ctrl-C does: scripts/study.sh killed while its participant plays leaves no jackd,
sclang or scsynth running. (Python's default for SIGTERM is to die at once, its finally blocks
unrun: the three played on, the server at a fifth of a core, until killed by hand.) Its scratch
folder, with its logs, is kept and named (kfharness.scratch), as for any job that failed."""
import signal
import subprocess
import time
from pathlib import Path

from kfharness import paths, procs, scratch


def name_of(pid):
    try:
        return Path(f"/proc/{pid}/comm").read_text().strip()
    except OSError:
        return None


def test_the_study_job_stopped_by_sigterm_leaves_nothing_running():
    out = paths.work_dir() / "stopped-study"
    log_path = paths.work_dir() / "stopped-study.log"
    seen = {}  # pid -> name: every process below the job while it ran
    tmp = paths.work_dir() / "stopped-study-tmp"  # where the job makes its scratch folder
    tmp.mkdir(exist_ok=True)
    with open(log_path, "w") as log:
        job = subprocess.Popen(["bash", str(paths.REPO_DIR / "scripts" / "study.sh"), "--out", str(out),
                                "--participants", "1", "--explore-s", "60", "--trials", "0"],
                               stdout=log, stderr=subprocess.STDOUT, env=scratch.job_environment(tmp))
    try:
        # Until its server has played a while (set-up, sclang's start and the boot come first).
        deadline, playing_since = time.monotonic() + 240, None
        while job.poll() is None and time.monotonic() < deadline:
            for pid in procs.descendants(job.pid):
                # The latest name: scsynth starts as a shell that execs it (Server.program).
                seen[pid] = name_of(pid) or seen.get(pid)
            if playing_since is None and "scsynth" in seen.values():
                playing_since = time.monotonic()
            if playing_since is not None and time.monotonic() - playing_since > 3:
                break
            time.sleep(0.2)
        running = sorted(set(seen.values()) - {None})
        assert {"jackd", "sclang", "scsynth"} <= set(running), (running, log_path.read_text()[-3000:])
        job.send_signal(signal.SIGTERM)
        # The job stops sclang (2 s to quit), its server (5 s) and jackd before it exits.
        code = job.wait(timeout=30)
        left = [(pid, name) for pid, name in seen.items() if procs.pid_alive(pid) and name_of(pid) == name]
        assert not left, f"still running after the job ended ({code}): {left}"
        assert code == 128 + signal.SIGTERM, (code, log_path.read_text()[-3000:])
        kept = scratch.job_folders(tmp)
        assert len(kept) == 1 and any(kept[0].glob("jackd-*.log")), f"no scratch folder with the job's logs: {kept}"
        assert f"scratch folder kept: {kept[0]}" in log_path.read_text(), log_path.read_text()[-2000:]
    finally:
        if job.poll() is None:  # the test failed before its SIGTERM, or the job did not end after it
            job.terminate()
            try:
                job.wait(30)
            except subprocess.TimeoutExpired:
                job.kill()
                job.wait()
        for pid, name in seen.items():
            if procs.pid_alive(pid) and name_of(pid) == name:
                procs.stop_pid(pid)
