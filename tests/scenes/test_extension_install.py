"""The extension folder as SuperCollider users install it: KF_EXTENSION_DIR=user is the folder
sclang's Platform.userExtensionDir names (cmake/UserExtensionDir.cmake, on this system), and the
installed folder is a quark whose classes and help Quarks.install would add."""
import os
import re
import subprocess

from kfharness import paths, sclang


def test_user_extension_dir_is_sclangs_and_the_folder_is_a_quark():
    cmake = subprocess.run(["cmake", "-DKF_EXTENSION_DIR=user", "-P", str(paths.REPO_DIR / "cmake" / "UserExtensionDir.cmake")],
                           capture_output=True, text=True, check=True, env=os.environ)
    configured = cmake.stdout.strip().removeprefix("-- Extension folder: ")
    ext = paths.extension_dir()
    out = sclang.run_script(f"""
        var quark = Quark.fromLocalPath({sclang.sc_string(ext)});
        "USER-EXTENSIONS %".format(Platform.userExtensionDir).postln;
        "QUARK % % %".format(quark.name, quark.version, quark.data['schelp']).postln;
        "QUARK-HELP %".format(File.exists(quark.localPath +/+ "HelpSource" +/+ quark.data['schelp'] ++ ".schelp")).postln;
        "QUARK-CLASSES %".format(File.exists(quark.localPath +/+ "Classes/Device/FrictionDevice.sc")).postln;
    """)
    line = next(l for l in out.splitlines() if l.startswith("USER-EXTENSIONS "))
    assert configured == line.removeprefix("USER-EXTENSIONS ") + "/KineticFriction"
    version = re.search(r"project\(KineticFriction VERSION ([0-9.]+)", (paths.REPO_DIR / "CMakeLists.txt").read_text())[1]
    assert f"QUARK KineticFriction {version} Overviews/KineticFriction" in out
    assert "QUARK-HELP true" in out
    assert "QUARK-CLASSES true" in out


def test_generated_defaults_are_the_profiles_numbers_as_written():
    """The classes made from profiles/paper.json carry its numbers as it writes them (0.14, not
    CMake's 0.14000000000000001): what a user reads in the source and every file written from
    the defaults."""
    classes = paths.extension_dir() / "Classes"
    profile = (paths.REPO_DIR / "profiles" / "paper.json").read_text()
    generated = ["UGens/LoudnessToFriction.sc", "UGens/FrictionPattern.sc", "PaperProfile.sc"]
    noisy = [(name, number) for name in generated
             for number in re.findall(r"\d+\.\d{12,}", (classes / name).read_text())]
    assert not noisy, noisy
    assert "loForce = 0.14," in (classes / "UGens" / "LoudnessToFriction.sc").read_text() and '"loForceN": 0.14,' in profile


def test_installed_classes_are_the_sources_each_once():
    """The installed Classes folder holds sc-classes/ as laid out (a folder per role), the
    templates' classes in their template's folder and PaperProfile.sc, and nothing else: a class
    file an earlier install left elsewhere (before a move or a rename) would make sclang stop at a
    duplicate class (cmake/RemoveStaleClasses.cmake removes it)."""
    sources = paths.REPO_DIR / "sc-classes"
    expected = {str(p.relative_to(sources)).removesuffix(".in") for p in [*sources.rglob("*.sc"), *sources.rglob("*.sc.in")]}
    expected.add("PaperProfile.sc")
    installed = [str(p.relative_to(paths.extension_dir() / "Classes")) for p in (paths.extension_dir() / "Classes").rglob("*.sc")]
    assert sorted(installed) == sorted(expected)
    names = [p.rsplit("/", 1)[-1] for p in installed]
    assert len(names) == len(set(names)), sorted(names)
