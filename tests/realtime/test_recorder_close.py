"""A condition's audio.wav closed and the next one started at once (FrictionStudyAudio.close, what
FrictionStudySession does between conditions, five sessions at a time in the study job): every
file is a whole WAV with the seconds recorded. Recorder.stopRecording in its place: take2 had no
frame; a probe of the same pattern left 7 of 10 files 0 bytes ("could not be opened: Format not
recognised"), as one condition's audio.wav was in a fresh clone's study job. The closed buffer's
number went back to sclang before the server freed it, and that late free emptied the next
recording's buffer."""
import numpy as np
import soundfile

from kfharness import paths, sclang

RECORDINGS = 10
SECONDS = 0.3


def test_back_to_back_recordings_each_keep_their_file(jack):
    folder = paths.work_dir() / "recorder-close"
    folder.mkdir(exist_ok=True)
    for old in folder.glob("*.wav"):
        old.unlink()
    sclang.require_ok(sclang.run_with_server(f"""
        var recorder;
        {{ Out.ar(0, SinOsc.ar([220, 330]) * 0.1) }}.play;
        {RECORDINGS}.do {{ |i|
            recorder = FrictionStudyAudio(s, {sclang.sc_string(str(folder))} +/+ "take" ++ i ++ ".wav", 0, 2);
            {SECONDS}.wait;
            recorder.close;
        }};
        s.sync;
    """, jack, name="recorder-close"))
    for i in range(RECORDINGS):
        path = folder / f"take{i}.wav"
        data, rate = soundfile.read(str(path), always_2d=True)  # a 0-byte file raises here
        assert rate == jack.sample_rate and data.shape[1] == 2, path
        # Most of the recorded time is in the file (DiskOut writes in half-buffer chunks; the close
        # writes the rest), and it is the sines, not silence.
        assert data.shape[0] >= 0.5 * SECONDS * rate and np.abs(data).max() > 0.05, (path, data.shape)
