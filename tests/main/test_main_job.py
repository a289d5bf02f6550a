"""scripts/main.sh, the README's first command, with one mapping: it sets up, builds and writes
the pilot's outputs (audio and force WAVs, CSVs, plots, recordings, the summary, the live view's
screenshot) into KF_MAIN_JOB_OUT, and removes its scratch folder (kfharness.scratch: 113 MB in /tmp
each run while it kept them)."""
import os
import shutil
import subprocess
from pathlib import Path

from kfharness import paths, scratch
from kfstudy import readers

OUT = Path(os.environ["KF_MAIN_JOB_OUT"])


def test_the_main_job_writes_the_pilot():
    shutil.rmtree(OUT, ignore_errors=True)
    # Its scratch folder in a folder of this test's, made as a user's job makes it.
    tmp = paths.work_dir() / "main-job-tmp"
    tmp.mkdir(exist_ok=True)
    run = subprocess.run(["bash", str(paths.REPO_DIR / "scripts" / "main.sh"), "--out", str(OUT),
                          "--mappings", "mapping1"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                         timeout=840, env=scratch.job_environment(tmp))
    assert run.returncode == 0, run.stdout[-4000:]
    left = [f"{p.name}: {len(list(p.iterdir()))} files" for p in scratch.job_folders(tmp)]
    assert not left, f"the job left its scratch folder in {tmp}: {left}"
    assert "== pilot done" in run.stdout
    for friction in ("off", "on"):
        base = f"mapping1-friction-{friction}"
        for suffix in ("-audio.wav", "-force.wav", ".csv", ".png", "-session.txt"):
            path = OUT / (base + suffix)
            assert path.is_file() and path.stat().st_size > 0, f"{path.name} missing or empty"
        data, rate = readers.read_wav(OUT / f"{base}-audio.wav")
        assert rate == 48000 and data.shape[1] == 2 and abs(data).max() > 0.5, "no pilot audio"
        header, records = readers.read_session(OUT / f"{base}-session.txt")
        assert any(tag == "F" for tag, _ in records), "no force frames recorded"
    summary = (OUT / "summary.md").read_text()
    assert "| mapping1 |" in summary and "mapping2" not in summary.split("## Crossing times")[1].split("## Friction")[0]
    # The live view needs a realtime server and a virtual display: both are installed by the set-up.
    assert (OUT / "view.png").is_file(), "the view screenshot was not written:\n" + run.stdout[-2000:]
