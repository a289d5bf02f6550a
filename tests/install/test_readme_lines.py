"""README.md's lines for installing and running, as a new user runs them: taken from the README
itself (an edit to it is what runs), in a fresh copy of the repository (its files as a clone
checks them out, no build), each install in a HOME of its own with a login's environment, first
as an unprivileged user (uid 65534 through setpriv: no rights, a HOME that is not the machine's),
then as root in the same copy. After each install, sclang started as the user starts it finds
the classes where the install put them (the generated ones included, the bench's not, none
twice), and scsynth loads the plugin.

What the test does with each of the README's blocks, by section:
- the first: its `scripts/main.sh` line runs as written (the main job sets up and builds what it
  runs, then renders the pilot); `scripts/test.sh` is the command this test runs in, and
  tests/main/test_gallery runs `scripts/gallery.sh`.
- "Using the extension": its shell lines run as written (the set-up, the folder sclang names
  through scripts/user-extension-dir.scd, the link into it); then, in another HOME, its
  Quarks.install line with the copy's path for the README's placeholder.
- "Installing as SuperCollider users do": its line runs as written (-DKF_EXTENSION_DIR=user).
- "A real mouse (Linux)": the udev lines need a running udev, which this machine has not: the
  test checks that the file they copy is the repository's rules file and that each udevadm
  command is one udevadm knows. udev applying the rules is tested in the QEMU guest with udev of
  issue 37 (tests/kernel), not here.
- "Other commands": a developer's commands, not an install's.
A block in any other section fails the test until this test says what to do with it."""
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from as_user import UNPRIVILEGED_UID, User, chown_tree, find_extension, fresh_copy, readme_blocks
from kfharness import paths, profile

SECTIONS = {"KineticFriction": "first", "Using the extension": "install", "A real mouse (Linux)": "udev",
            "Installing as SuperCollider users do": "cmake", "Other commands": "developer"}
QUARK_PLACEHOLDER = "/path/to/the/clone"
BUILD_S = 900  # a build of the plugin from nothing on a busy 2-core machine, with room


def blocks_of(kind, language="sh"):
    return [text for section, lang, text in readme_blocks() if SECTIONS.get(section) == kind and lang == language]


def test_every_readme_block_is_one_this_test_knows():
    unknown = [(section, lang) for section, lang, _ in readme_blocks() if section not in SECTIONS]
    assert not unknown, f"README blocks this test does not know what to do with: {unknown}"
    assert len(blocks_of("install")) == 1 and len(blocks_of("cmake")) == 1 and len(blocks_of("udev")) == 1
    assert len(blocks_of("install", "supercollider")) == 1


def test_the_udev_lines_copy_the_repositorys_rules_with_udevadms_commands():
    (udev,) = blocks_of("udev")
    copies = re.findall(r"\bcp (\S+) /etc/udev/rules\.d/", udev)
    assert copies, f"no rules file copied:\n{udev}"
    for source in copies:
        assert (paths.REPO_DIR / source).is_file(), f"{source} is not in the repository"
    commands = re.findall(r"\budevadm (\w+)", udev)
    assert commands, f"no udevadm command:\n{udev}"
    for command in commands:
        known = subprocess.run(["udevadm", command, "--help"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               text=True)
        assert known.returncode == 0, f"udevadm has no command {command}: {known.stdout}"


@pytest.fixture(scope="module")
def copy():
    path = fresh_copy()
    if os.geteuid() == 0:
        chown_tree(path, UNPRIVILEGED_UID)
    yield path
    shutil.rmtree(path.parent)  # the copy with its build and the HOMEs beside it: hundreds of MB


def users():
    """The unprivileged user first (its build is the fresh one), then root in the same copy."""
    return [pytest.param(UNPRIVILEGED_UID, id="unprivileged"), pytest.param(0, id="root")]


def check_found(found, classes_dir, what):
    """The extension's classes from classes_dir (or its role folders), the bench's nowhere, the plugin loaded."""
    assert found.classes, f"{what}: sclang ran no check (its class library did not compile?):\n{found.output[-4000:]}"
    assert "duplicate" not in found.output.lower(), f"{what}: classes compiled twice:\n{found.output[-4000:]}"
    assert found.classes.pop("KFBenchClock") == "none", f"{what}: the bench's class was installed"
    for name, path in found.classes.items():
        assert Path(path).is_relative_to(classes_dir), f"{what}: {name} from {path}, not {classes_dir}"
    assert found.lo_force == pytest.approx(profile.mapping()["loForceN"]), f"{what}: the profile's classes"
    assert found.level == pytest.approx(profile.mapping()["loForceN"]), \
        f"{what}: the plugin did not render:\n{found.render_output[-3000:]}"


@pytest.mark.parametrize("uid", [p.values[0] for p in users()], ids=[p.id for p in users()])
def test_the_readmes_lines_install_and_run_as_written(copy, uid):
    if os.geteuid() != 0 and uid != os.geteuid():
        pytest.skip("switching users needs root")
    user = User(uid if os.geteuid() == 0 else os.geteuid(), copy.parent)

    # The main job, as the first block writes it.
    (first,) = blocks_of("first")
    main_lines = [line for line in first.splitlines() if line.startswith("scripts/main.sh")]
    assert len(main_lines) == 1, first
    home = user.fresh_home()
    run = user.bash(main_lines[0] + "\n", home, copy, timeout=BUILD_S)
    assert run.returncode == 0, f"{user.name}: {main_lines[0]}\n{run.stdout[-4000:]}"
    assert (copy / "out" / "pilot" / "summary.md").is_file(), f"{user.name}: no pilot summary\n{run.stdout[-2000:]}"

    # "Using the extension": the link into the user's extensions.
    (install,) = blocks_of("install")
    home = user.fresh_home()
    run = user.bash(install, home, copy, timeout=BUILD_S)
    assert run.returncode == 0, f"{user.name}: the link lines failed\n{install}\n{run.stdout[-4000:]}"
    found = find_extension(user, home, copy)
    assert found.extensions and Path(found.extensions).is_relative_to(home), found.output[-3000:]
    link = Path(found.extensions) / "KineticFriction"
    assert link.resolve() == (copy / "build" / "KineticFriction").resolve(), \
        f"{user.name}: nothing linked where sclang looks ({found.extensions})\n{run.stdout[-2000:]}"
    check_found(found, link / "Classes", f"{user.name}, linked")

    # The quark: the README's Quarks.install line, the copy's path for its placeholder.
    (quark_block,) = blocks_of("install", "supercollider")
    assert QUARK_PLACEHOLDER in quark_block, quark_block
    home = user.fresh_home()
    script = home / "install-quark.scd"
    script.write_text(quark_block.replace(QUARK_PLACEHOLDER, str(copy)) + "\n0.exit;\n")
    os.lchown(script, user.uid, user.uid)
    headless = {"QT_QPA_PLATFORM": "offscreen", "QTWEBENGINE_DISABLE_SANDBOX": "1",
                "XDG_RUNTIME_DIR": f"/tmp/kf-xdg-{user.uid}"}
    run = user.run(["sclang", str(script)], home, copy, timeout=120, env=headless)
    assert "KineticFriction installed" in run.stdout, f"{user.name}: Quarks.install\n{run.stdout[-3000:]}"
    found = find_extension(user, home, copy, add_plugin_path=True)
    check_found(found, copy / "build" / "KineticFriction" / "Classes", f"{user.name}, quark")

    # "Installing as SuperCollider users do": cmake puts it into the user's extensions.
    (cmake_block,) = blocks_of("cmake")
    home = user.fresh_home()
    run = user.bash(cmake_block, home, copy, timeout=BUILD_S)
    assert run.returncode == 0, f"{user.name}: the cmake lines failed\n{cmake_block}\n{run.stdout[-4000:]}"
    found = find_extension(user, home, copy)
    installed = Path(found.extensions or "/nonexistent") / "KineticFriction"
    assert installed.is_dir() and not installed.is_symlink(), f"{user.name}: not installed\n{run.stdout[-2000:]}"
    check_found(found, installed / "Classes", f"{user.name}, cmake --install")
