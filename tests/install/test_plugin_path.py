"""KineticFriction.addPluginPath keeps scsynth's own plugin search: another extension's plugin in
the user's Extensions folder (other_extension/, built with the tests, lying where sc3-plugins
would) loads beside KineticFriction's, which the server takes from the build folder (not
installed). ugenPluginsPath is scsynth's -U, which replaces its search: when addPluginPath set
it to the system plugins and ours alone, the other extension's UGen was "not installed".

The user is a HOME of the test's own; sclang writes the server's options as addPluginPath left
them and scsynth -N renders with exactly those (as Score.recordNRT and Server.boot pass them)."""
import os
import shlex
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from kfharness import paths, profile, sclang
from kfstudy import readers

OTHER_PLUGIN = Path(os.environ["KF_OTHER_EXTENSION_PLUGIN"])
OTHER_CLASS = Path(__file__).parent / "other_extension" / "OtherExtensionDC.sc"
OTHER_LEVEL = 0.25  # what OtherExtensionDC outputs


def user_home():
    """A HOME with the other extension in its Extensions folder (Linux's default place)."""
    assert OTHER_PLUGIN.is_file(), f"{OTHER_PLUGIN} not built (the OtherExtension target of tests/install)"
    home = Path(tempfile.mkdtemp(prefix="kf-home-", dir=paths.work_dir()))
    other = home / ".local" / "share" / "SuperCollider" / "Extensions" / "OtherExtension"
    (other / "plugins").mkdir(parents=True)
    (other / "Classes").mkdir()
    shutil.copy(OTHER_PLUGIN, other / "plugins")
    shutil.copy(OTHER_CLASS, other / "Classes")
    return home


def test_another_extensions_plugin_loads_beside_ours():
    home = user_home()
    env = {"HOME": str(home), "XDG_DATA_HOME": None, "XDG_CONFIG_HOME": None}
    score_path = paths.work_dir() / "plugin-path.osc"
    wav_path = paths.work_dir() / "plugin-path.wav"
    out = sclang.run_script(f"""
        var options = KineticFriction.addPluginPath(ServerOptions.new.numOutputBusChannels_(2));
        var def = SynthDef(\\kfBoth, {{ Out.ar(0, [OtherExtensionDC.ar, LoudnessToFriction.ar(DC.ar(0))]) }});
        Score([
            [0, ['/d_recv', def.asBytes]],
            [0, Synth.basicNew(\\kfBoth, s, 1000).newMsg],
            [0.05, ['/c_set', 0, 0]]
        ]).writeOSCFile({sclang.sc_string(score_path)});
        ("KF-EXTENSIONS " ++ Platform.userExtensionDir).postln;
        ("KF-OPTIONS " ++ options.asOptionsString).postln;
    """, name="plugin-path", env=env)
    lines = dict(line.split(" ", 1) for line in out.splitlines() if line.startswith(("KF-EXTENSIONS ", "KF-OPTIONS ")))
    # The other extension lies where this user's sclang and scsynth look.
    assert Path(lines["KF-EXTENSIONS"]) == home / ".local/share/SuperCollider/Extensions"
    options = shlex.split(lines["KF-OPTIONS"])
    print("server options:", " ".join(options))
    server_env = {**{k: v for k, v in os.environ.items() if k not in env}, "HOME": str(home)}
    if sclang.server_preload():  # a sanitized plugin (scripts/check.sh sanitize-plugin)
        server_env["LD_PRELOAD"] = sclang.server_preload()
    run = subprocess.run(["scsynth", "-N", str(score_path), "_", str(wav_path), "48000", "WAV", "float", *options],
                         stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                         timeout=120, env=server_env)
    assert run.returncode == 0, run.stdout[-3000:]
    assert "not installed" not in run.stdout, f"a plugin did not load:\n{run.stdout[-3000:]}"
    data, _ = readers.read_wav(wav_path)
    assert len(data) >= 2000
    assert np.all(data[:, 0] == np.float32(OTHER_LEVEL)), "the other extension's UGen did not run"
    # Silence maps to the lowest friction (equation 2's loForce).
    assert np.allclose(data[:, 1], profile.mapping()["loForceN"]), "KineticFriction's UGen did not run"
