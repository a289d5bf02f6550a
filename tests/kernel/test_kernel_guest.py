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

from kfharness import guest

PROGRAM = os.environ.get("KF_KERNEL_TESTS", "")
GADGET = os.environ.get("KF_BOARD_GADGET", "")  # the board's firmware as a USB gadget, started by the tests
ARTEFACTS = Path(os.environ.get("KF_TEST_ARTEFACTS_DIR", "/tmp")) / "kernel"

# What the guest needs: the USB host controller and HID stack for QEMU's mice, uhid for devices
# made from report descriptors, evdev, and psmouse for the PC's built-in PS/2 mouse (a mouse
# that is no USB one, for the order of the mice); dummy_hcd (a USB device controller wired to a
# host controller of its own), libcomposite and FunctionFS for the friction board's gadget.
MODULES = ["xhci-pci", "usbhid", "hid-generic", "uhid", "evdev", "psmouse", "dummy_hcd", "libcomposite", "usb_f_fs"]
# QEMU's USB mouse on port 1 of an xHCI controller (the tests plug a twin in port 2 and unplug
# and replug this one through QMP), and a USB keyboard on port 3 (a node that reports keys).
QEMU_DEVICES = ["-device", "qemu-xhci,id=xhci", "-device", "usb-mouse,bus=xhci.0,port=1,id=mouse1",
                "-device", "usb-kbd,bus=xhci.0,port=3,id=keyboard1"]


def case_names():
    """The Catch2 cases, listed by the program itself on this machine."""
    if not PROGRAM:
        return ["(KF_KERNEL_TESTS not set: run through ctest)"]
    # Catch2 v2 exits with the number of cases listed.
    listed = subprocess.run([PROGRAM, "--list-test-names-only"], capture_output=True, text=True)
    return [line.strip() for line in listed.stdout.splitlines() if line.strip()]


@pytest.fixture(scope="module")
def guest_run():
    assert PROGRAM, "KF_KERNEL_TESTS is not set (run the group through ctest)"
    ARTEFACTS.mkdir(parents=True, exist_ok=True)
    spec = guest.GuestSpec(
        programs=[("kernel_tests", [PROGRAM, "--reporter", "junit", "--out", "/results/kernel_tests.xml",
                                    "--durations", "yes"])],
        executables=[GADGET], modules=MODULES, udev_rules=[os.environ["KF_UDEV_RULES"]],
        files=[Path(os.environ["KF_TEST_DATA_DIR"]) / "hid"], qemu_args=QEMU_DEVICES)
    run = guest.run(spec, ARTEFACTS)
    (ARTEFACTS / "console.log").write_text(run.console)
    for name, data in run.files.items():
        (ARTEFACTS / name).write_bytes(data)
    figures = run.files.get("figures.txt", b"").decode()
    print(f"\nguest: kernel {run.kernel}, booted in {run.boot_s:.1f} s, ran in {run.wall_s:.1f} s "
          f"(QEMU start to done); {len(run.qmp_log)} QMP commands\n{figures}")
    return run


def results(run):
    """Catch2's JUnit report: case name -> list of failure texts (empty: passed)."""
    data = run.files.get("kernel_tests.xml")
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
    assert "kernel_tests" in guest_run.exits, f"kernel_tests did not run\nconsole:\n{guest_run.console_tail()}"
    assert "kernel_tests.xml" in guest_run.files, (
        f"kernel_tests exited {guest_run.exits['kernel_tests']} without its report\n"
        f"console:\n{guest_run.console_tail()}")


@pytest.mark.parametrize("case", case_names())
def test_case(guest_run, case):
    if guest_run.failure:
        pytest.fail(f"the guest run failed: {guest_run.failure}\nconsole:\n{guest_run.console_tail()}")
    cases = results(guest_run)
    if cases is None:
        pytest.fail(f"no results: kernel_tests exited {guest_run.exits.get('kernel_tests')}\n"
                    f"console:\n{guest_run.console_tail()}")
    if case not in cases:
        pytest.fail(f"'{case}' did not run in the guest\nconsole:\n{guest_run.console_tail()}")
    failures = cases[case]
    assert not failures, "\n\n".join(failures)
