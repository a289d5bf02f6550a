"""What the install tests share: README.md's code blocks, a fresh copy of the repository, users
(root, and an unprivileged one through setpriv) each with a HOME of their own and the
environment a login gives (no variable of the test's), and the check that sclang finds the
extension's classes and scsynth its plugin."""
import os
import re
import shlex
import shutil
import subprocess
import tempfile
from pathlib import Path

from kfharness import paths
from kfstudy import readers

UNPRIVILEGED_UID = 65534  # nobody: no rights, no home, no group but its own


def readme_blocks(readme=None):
    """[(section heading, language, text)] of every fenced block of README.md, in order."""
    text = Path(readme or paths.REPO_DIR / "README.md").read_text()
    blocks, section = [], ""
    for match in re.finditer(r"^(#+ [^\n]*)$|^```(\w*)\n(.*?)^```$", text, re.M | re.S):
        if match.group(1):
            section = match.group(1).lstrip("#").strip()
        else:
            blocks.append((section, match.group(2), match.group(3)))
    return blocks


def fresh_copy():
    """The repository's files as a clone checks them out (tracked and new, not ignored: no build
    folder), in a folder every user can reach. Returns its path."""
    base = Path(tempfile.mkdtemp(prefix="kf-fresh-"))
    base.chmod(0o755)
    copy = base / "KineticFriction"
    files = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                           cwd=paths.REPO_DIR, stdout=subprocess.PIPE, check=True).stdout.split(b"\0")
    for name in filter(None, (f.decode() for f in files)):
        source = paths.REPO_DIR / name
        if source.is_file():  # not a file deleted in the work tree
            (copy / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, copy / name)
    return copy


def chown_tree(path, uid):
    for root, dirs, files in os.walk(path):
        for name in [root, *(os.path.join(root, n) for n in dirs + files)]:
            os.lchown(name, uid, uid)


class User:
    """Runs commands as `uid` (0: root), with a login's environment: PATH, HOME, LANG. Its HOMEs
    are made in `base` (removed with it)."""

    def __init__(self, uid, base):
        self.uid = uid
        self.base = Path(base)
        self.name = "root" if uid == 0 else f"uid {uid}"

    def fresh_home(self):
        home = Path(tempfile.mkdtemp(prefix=f"home-{self.uid}-", dir=self.base))
        chown_tree(home, self.uid)
        return home

    def environment(self, home):
        return {"PATH": "/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin", "HOME": str(home),
                "LANG": "C.UTF-8", "USER": "root" if self.uid == 0 else "nobody"}

    def run(self, command, home, cwd, timeout, env=None):
        """`command` (a list) as this user; returns the CompletedProcess (stdout and stderr as one)."""
        prefix = [] if self.uid == os.geteuid() else [
            "setpriv", f"--reuid={self.uid}", f"--regid={self.uid}", "--clear-groups", "--"]
        return subprocess.run(prefix + list(command), cwd=cwd, env={**self.environment(home), **(env or {})},
                              stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              text=True, errors="replace", timeout=timeout)

    def bash(self, script, home, cwd, timeout):
        """A README block's lines, run by bash as written (errexit: a failing line fails the block)."""
        path = Path(home) / "readme-block.sh"
        path.write_text("set -eo pipefail\n" + script)
        os.lchown(path, self.uid, self.uid)
        return self.run(["bash", str(path)], home, cwd, timeout)


# sclang started as the user starts it (no -l: the default configuration, its includePaths and
# Extensions folders): where each class comes from, and a Score of the plugin's UGen written with
# the server options a user would boot with.
CHECK_SCRIPT = r"""
var options = ServerOptions.new.numOutputBusChannels_(1);
[\FrictionDevice, \FrictionPattern, \LoudnessToFriction, \FrictionPilot, \KineticFriction, \KFBenchClock].do { |name|
	var found = name.asClass;
	"KF-CLASS % %".format(name, found !? { found.filenameSymbol } ? "none").postln;
};
"KF-EXTENSIONS %".format(Platform.userExtensionDir).postln;
"KF-LOFORCE %".format(KineticFriction.paperMapping.loForceN).postln;
if(@ADD_PLUGIN_PATH@) { KineticFriction.addPluginPath(options) };
Score([
	[0, ['/d_recv', SynthDef(\kfInstalled, { Out.ar(0, LoudnessToFriction.ar(DC.ar(0))) }).asBytes]],
	[0, Synth.basicNew(\kfInstalled, s, 1000).newMsg],
	[0.05, ['/c_set', 0, 0]]
]).writeOSCFile(@SCORE@);
"KF-OPTIONS %".format(options.asOptionsString).postln;
"KF-CHECK-DONE".postln;
0.exit;
"""


class Found:
    """What CHECK_SCRIPT and its render found, for one user and one HOME."""

    def __init__(self, output, render_output, level):
        self.output = output
        self.render_output = render_output
        self.level = level
        self.classes = dict(line.split()[1:3] for line in output.splitlines() if line.startswith("KF-CLASS "))
        self.extensions = next((line.split(" ", 1)[1] for line in output.splitlines()
                                if line.startswith("KF-EXTENSIONS ")), None)
        self.lo_force = next((float(line.split()[1]) for line in output.splitlines()
                              if line.startswith("KF-LOFORCE ")), None)


def find_extension(user, home, cwd, add_plugin_path=False):
    """Runs CHECK_SCRIPT as `user` in `home`, then renders its Score with scsynth -N and the options
    it posted; returns a Found."""
    script = Path(home) / "kf-check.scd"
    score = Path(home) / "kf-check.osc"
    wav = Path(home) / "kf-check.wav"
    script.write_text(CHECK_SCRIPT.replace("@ADD_PLUGIN_PATH@", "true" if add_plugin_path else "false")
                      .replace("@SCORE@", '"' + str(score) + '"'))
    os.lchown(script, user.uid, user.uid)
    # Headless (no display, and as root), as README's scripts/env.sh sets it.
    headless = {"QT_QPA_PLATFORM": "offscreen", "QTWEBENGINE_DISABLE_SANDBOX": "1",
                "XDG_RUNTIME_DIR": f"/tmp/kf-xdg-{user.uid}"}
    Path(headless["XDG_RUNTIME_DIR"]).mkdir(mode=0o700, exist_ok=True)
    os.lchown(headless["XDG_RUNTIME_DIR"], user.uid, user.uid)
    try:
        output = user.run(["sclang", str(script)], home, cwd, timeout=120, env=headless).stdout
    except subprocess.TimeoutExpired as timeout:  # a class library that did not compile waits
        output = (timeout.stdout or b"").decode(errors="replace") + "\n(sclang timed out)"
    options = next((line.split(" ", 1)[1] for line in output.splitlines() if line.startswith("KF-OPTIONS ")), None)
    if "KF-CHECK-DONE" not in output or options is None:
        return Found(output, "", None)
    render = user.run(["scsynth", "-N", str(score), "_", str(wav), "48000", "WAV", "float", *shlex.split(options)],
                      home, cwd, timeout=120)
    level = None
    if render.returncode == 0 and wav.exists():
        data, _ = readers.read_wav(wav)
        level = float(data[:, 0].mean()) if len(data) else None
    return Found(output, render.stdout, level)
