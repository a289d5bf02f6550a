"""The kernel group: one boot of a QEMU guest runs every Catch2 case of kernel_tests (tests/kernel)
against Debian's kernel, systemd-udevd with our rules, the real hidapi and evdev, uhid and QEMU's
USB devices; each case is reported here as a test of its own. A guest that does not boot, a module
that does not load, a program that does not run or a case missing from its results fails, with
the reason and the guest console's tail (never a skip). README.md beside this file says how to add
a test."""
import os
import subprocess
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import pytest

import scene_host
from kfharness import guest, procs

PROGRAM = os.environ.get("KF_KERNEL_TESTS", "")
GADGET = os.environ.get("KF_BOARD_GADGET", "")  # the board's firmware as a USB gadget, started by the tests
# The scene (scene/test_pilot_scene.cpp, with scene_host.py here): built where the plugin is.
SCENE = os.environ.get("KF_KERNEL_SCENE", "")
SCENE_SERVERS = [os.environ.get("KF_SCSYNTH", ""), os.environ.get("KF_JACKD", ""),
                 os.environ.get("KF_JACK_DUMMY", ""), os.environ.get("KF_PLUGIN", "")]
SC_PLUGINS = Path(os.environ.get("KF_SC_SYSTEM_PLUGINS", "/usr/lib/SuperCollider/plugins"))
ARTEFACTS = Path(os.environ.get("KF_TEST_ARTEFACTS_DIR", "/tmp")) / "kernel"

# What the guest needs: the USB host controller and HID stack for QEMU's mice, uhid for devices
# made from report descriptors, evdev, and psmouse for the PC's built-in PS/2 mouse (a mouse
# that is no USB one, for the order of the mice); dummy_hcd (a USB device controller wired to a
# host controller of its own), libcomposite and FunctionFS for the friction board's gadget.
MODULES = ["xhci-pci", "usbhid", "hid-generic", "uhid", "evdev", "psmouse", "dummy_hcd", "libcomposite", "usb_f_fs"]
# The scene's network: a virtio NIC on QEMU's user network, scsynth's port forwarded from the host.
SCENE_MODULES = ["virtio_pci", "virtio_net"]
# The whole guest run, boot to the last program, is guarded against a hang, not timed. Under TCG
# it took 163 s on an idle machine at 51ae098 (boot 17 s, kernel_tests 96 s, the scene 40 s) and
# overran a 200 s guard on CI's busy one: three times the idle run. (KVM, nested here, failed
# every case within 200 s, its time all in the host's kernel.)
HANG_GUARD_S = 480
# QEMU's USB mouse on port 1 of an xHCI controller (the tests plug a twin in port 2 and unplug
# and replug this one through QMP), and a USB keyboard on port 3 (a node that reports keys).
QEMU_DEVICES = ["-device", "qemu-xhci,id=xhci", "-device", "usb-mouse,bus=xhci.0,port=1,id=mouse1",
                "-device", "usb-kbd,bus=xhci.0,port=3,id=keyboard1"]


def programs():
    """The guest's test programs: name -> host path."""
    found = {"kernel_tests": PROGRAM}
    if SCENE:
        found["kernel_scene"] = SCENE
    return found


def case_names():
    """(program, case) of every Catch2 case, listed by the programs themselves on this machine."""
    if not PROGRAM:
        return [("kernel_tests", "(KF_KERNEL_TESTS not set: run through ctest)")]
    cases = []
    for name, path in programs().items():
        # Catch2 v2 exits with the number of cases listed.
        listed = subprocess.run([path, "--list-test-names-only"], capture_output=True, text=True)
        cases += [(name, line.strip()) for line in listed.stdout.splitlines() if line.strip()]
    return cases


@pytest.fixture(scope="module")
def guest_run():
    assert PROGRAM, "KF_KERNEL_TESTS is not set (run the group through ctest)"
    ARTEFACTS.mkdir(parents=True, exist_ok=True)
    executables, modules, qemu_args, hooks = [GADGET], list(MODULES), list(QEMU_DEVICES), {}
    if SCENE:
        port = procs.free_udp_port()
        hooks["scene"] = scene_host.SceneHost(port, ARTEFACTS)
        executables += SCENE_SERVERS + sorted(str(p) for p in SC_PLUGINS.glob("*.so") if "_supernova" not in p.name)
        modules += SCENE_MODULES
        qemu_args += ["-netdev", f"user,id=net0,hostfwd=udp:127.0.0.1:{port}-:57110",
                      "-device", "virtio-net-pci,netdev=net0"]
    spec = guest.GuestSpec(
        programs=[(name, [path, "--reporter", "junit", "--out", f"/results/{name}.xml", "--durations", "yes"])
                  for name, path in programs().items()],
        executables=executables, modules=modules, udev_rules=[os.environ["KF_UDEV_RULES"]],
        files=[Path(os.environ["KF_TEST_DATA_DIR"]) / "hid"], qemu_args=qemu_args, hooks=hooks,
        timeout_s=HANG_GUARD_S)
    try:
        run = guest.run(spec, ARTEFACTS)
    finally:
        for hook in hooks.values():
            hook.close()
    (ARTEFACTS / "console.log").write_text(run.console)
    (ARTEFACTS / "run.txt").write_text(f"kernel {run.kernel}\nboot_s {run.boot_s:.1f}\nwall_s {run.wall_s:.1f}\n"
                                       f"failure {run.failure}\nlogs {run.logs}\nexits {run.exits}\n")
    for name, data in run.files.items():
        (ARTEFACTS / name).write_bytes(data)
    figures = run.files.get("figures.txt", b"").decode()
    print(f"\nguest: kernel {run.kernel}, booted in {run.boot_s:.1f} s, ran in {run.wall_s:.1f} s "
          f"(QEMU start to done); {len(run.qmp_log)} QMP commands\n{figures}")
    return run


def results(run, program):
    """Catch2's JUnit report of a program: case name -> list of failure texts (empty: passed)."""
    data = run.files.get(f"{program}.xml")
    if data is None:
        return None
    cases = {}
    for case in ElementTree.fromstring(data).iter("testcase"):
        name = case.get("name", "").split("/")[0]  # a section's name follows its case's
        failures = cases.setdefault(name, [])
        for failure in list(case.iter("failure")) + list(case.iter("error")):
            failures.append(f"{failure.get('message', '')}\n{failure.text or ''}".strip())
    return cases


def test_guest_booted_and_ran(guest_run):
    assert guest_run.failure is None, f"{guest_run.failure}\nconsole:\n{guest_run.console_tail()}"
    for program in programs():
        assert program in guest_run.exits, f"{program} did not run\nconsole:\n{guest_run.console_tail()}"
        assert f"{program}.xml" in guest_run.files, (
            f"{program} exited {guest_run.exits[program]} without its report\n"
            f"console:\n{guest_run.console_tail()}")


@pytest.mark.parametrize("program,case", case_names())
def test_case(guest_run, program, case):
    if guest_run.failure:
        pytest.fail(f"the guest run failed: {guest_run.failure}\nconsole:\n{guest_run.console_tail()}")
    cases = results(guest_run, program)
    if cases is None:
        pytest.fail(f"no results: {program} exited {guest_run.exits.get(program)}\n"
                    f"console:\n{guest_run.console_tail()}")
    if case not in cases:
        pytest.fail(f"'{case}' did not run in the guest\nconsole:\n{guest_run.console_tail()}")
    failures = cases[case]
    assert not failures, "\n\n".join(failures)


# The rig's own failures, without the test program: each must fail the run with its reason.
def test_a_guest_that_cannot_boot_fails_with_the_reason(tmp_path):
    # 24 MiB do not hold the kernel and the initramfs: the guest never reaches its /init.
    run = guest.run(guest.GuestSpec(programs=[("true", ["/usr/bin/true"])], memory_mb=24, timeout_s=60), tmp_path)
    assert run.failure and "the guest did not boot" in run.failure, run.failure


def test_a_module_the_kernel_does_not_have_fails_before_booting(tmp_path):
    run = guest.run(guest.GuestSpec(programs=[("true", ["/usr/bin/true"])], modules=["kf-no-such-module"]), tmp_path)
    assert run.failure and "module kf-no-such-module is not in /lib/modules/" in run.failure, run.failure
