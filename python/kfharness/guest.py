"""The kernel rig: a QEMU guest (TCG, no KVM) booting Debian's own kernel with the modules a run
asks for, systemd-udevd applying the rules given, the test programs built by the normal build run
in it, and their result files and exit statuses brought back. Everything comes from Debian
packages installed by scripts/setup.sh (linux-image-amd64, qemu-system-x86, busybox-static, udev
and the runtime libraries of the programs, found with ldd): nothing is downloaded.

The initramfs (uncompressed: TCG would spend longer unpacking than QEMU loading) holds busybox,
/init (guest_init.sh), systemd-udevd and udevadm, the programs and every library they load, the
modules with their dependencies, the udev rules and the extra files, each at its host path.

The host hook: the guest's second serial port (/dev/ttyS1) is a socket here. Lines from the guest:
  hello <kernel release>      /init runs
  log <text>                  progress, kept for the report
  error <text>                /init failed (a module that would not load, udevd): the run fails
  qmp <one-line JSON>         a QMP command for QEMU; the answer goes back as "qmp <JSON>\\n"
  host <name> <text>          a call of a host-side hook (GuestSpec.hooks[name](text) -> one line
                              of text), answered as "host <text>\\n"
  file <name> <size>          then <size> raw bytes: a result file
  exit <name> <status>        a program's exit status
  done                        all programs ran
So a test program in the guest drives QEMU itself (input-send-event, device_del, device_add: see
tests/kernel/guest/HostHook.hpp) and a run can add its own host-side actions.

Usage: run(GuestSpec(...), work_dir) -> GuestRun; GuestRun.failure is None when the guest booted,
loaded its modules, started udev and sent "done"; else the reason, with the console's tail.
"""
import json
import os
import re
import shlex
import socket
import stat
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

INIT_SCRIPT = Path(__file__).with_name("guest_init.sh")
# systemd-udevd's own rules a user's system applies to input and hidraw nodes (group and mode,
# ID_INPUT_*, by-id links, the seat and uaccess), from the udev and systemd packages.
HOST_UDEV_RULES = ["50-udev-default.rules", "60-input-id.rules", "60-persistent-input.rules", "71-seat.rules",
                   "73-seat-late.rules"]
UDEV_PROGRAMS = ["/lib/systemd/systemd-udevd", "/bin/udevadm"]
# The user at the seat (uid 1000), and the groups 50-udev-default.rules names for input nodes.
PASSWD = "root:x:0:0:root:/root:/bin/sh\nkfuser:x:1000:1000:seat user:/tmp:/bin/sh\n"
GROUP = "root:x:0:\ninput:x:101:\nkfuser:x:1000:\n"
SEAT0 = "ACTIVE=c1\nACTIVE_UID=1000\nSESSIONS=c1\nUIDS=1000\n"


@dataclass
class GuestSpec:
    programs: list  # [(name, [argv...])], run in order; argv[0] a host path, copied in with its libraries
    executables: list = field(default_factory=list)  # host programs a test starts itself, copied in with their libraries
    modules: list = field(default_factory=list)  # module names as modprobe takes them (hid-generic, uhid)
    udev_rules: list = field(default_factory=list)  # rule files of ours, into /etc/udev/rules.d/
    files: list = field(default_factory=list)  # host files or folders, copied in at the same path
    qemu_args: list = field(default_factory=list)  # devices: ["-device", "qemu-xhci,id=xhci", ...]
    hooks: dict = field(default_factory=dict)  # name -> function(text) -> one line of text
    seat_user: bool = True  # a user (uid 1000) at seat0, for udev's uaccess
    memory_mb: int = 512
    timeout_s: float = 200.0  # a hang guard for the whole run, not a timing tolerance


@dataclass
class GuestRun:
    failure: object = None  # None, or why the run failed (str)
    kernel: str = ""
    logs: list = field(default_factory=list)
    files: dict = field(default_factory=dict)  # name -> bytes
    exits: dict = field(default_factory=dict)  # program name -> exit status
    qmp_log: list = field(default_factory=list)  # (request, answer) in order
    console: str = ""
    boot_s: float = 0.0  # QEMU start to "hello"
    wall_s: float = 0.0  # QEMU start to "done"

    def console_tail(self, lines=40):
        return "\n".join(self.console.splitlines()[-lines:])


# --- what goes in ---------------------------------------------------------------------------

def kernel_release():
    """The newest Debian kernel that has both its image in /boot and its modules."""
    found = []
    for image in Path("/boot").glob("vmlinuz-*"):
        release = image.name[len("vmlinuz-"):]
        if (Path("/lib/modules") / release / "modules.dep").exists():
            found.append(release)
    if not found:
        raise GuestError("no Debian kernel with modules in /boot and /lib/modules: scripts/setup.sh installs "
                         "linux-image-amd64")
    return sorted(found, key=lambda r: [int(p) if p.isdigit() else p for p in re.split(r"[.-]", r)])[-1]


class GuestError(Exception):
    pass


def module_files(release, names):
    """The .ko files of the named modules and of everything they depend on, dependencies first
    (from modules.dep, as modprobe reads it). A name the kernel does not have is an error."""
    root = Path("/lib/modules") / release
    deps = {}
    for line in (root / "modules.dep").read_text().splitlines():
        path, _, rest = line.partition(":")
        deps[path] = rest.split()
    by_name = {Path(p).name.split(".ko")[0].replace("-", "_"): p for p in deps}
    builtin = set()
    if (root / "modules.builtin").exists():
        builtin = {Path(p).name.split(".ko")[0].replace("-", "_") for p in (root / "modules.builtin").read_text().split()}
    ordered = []

    def visit(path):
        if path in ordered:
            return
        for dep in reversed(deps[path]):  # modules.dep lists the one to load first last
            visit(dep)
        ordered.append(path)

    for name in names:
        key = name.replace("-", "_")
        if key in builtin:
            continue
        if key not in by_name:
            raise GuestError(f"module {name} is not in /lib/modules/{release} (neither a module nor built in)")
        visit(by_name[key])
    return [root / p for p in ordered]


def shared_libraries(executable):
    """Every library `executable` loads and its loader, from ldd."""
    out = subprocess.run(["ldd", str(executable)], capture_output=True, text=True)
    if out.returncode != 0:
        raise GuestError(f"ldd {executable}: {out.stderr.strip() or out.stdout.strip()}")
    libs = []
    for line in out.stdout.splitlines():
        line = line.strip()
        if "=>" in line:
            target = line.split("=>")[1].split("(")[0].strip()
            if target == "not found" or not target:
                if "not found" in line:
                    raise GuestError(f"{executable}: {line}")
                continue
            libs.append(target)
        elif line.startswith("/"):
            libs.append(line.split("(")[0].strip())
    return libs


class Cpio:
    """An uncompressed newc archive, written as entries are added; host paths keep their place
    (a symbolic link on the way, /lib -> usr/lib, is added as a link)."""

    def __init__(self):
        self.out = bytearray()
        self.names = set()
        self.inode = 1

    def _entry(self, name, mode, data=b""):
        name = name.lstrip("/")
        if name in self.names:
            return
        self.names.add(name)
        fields = [self.inode, mode, 0, 0, 1, 0, len(data), 0, 0, 0, 0, len(name) + 1, 0]
        self.inode += 1
        header = b"070701" + b"".join(b"%08X" % f for f in fields)
        self.out += header + name.encode() + b"\0"
        self.out += b"\0" * (-len(self.out) % 4)
        self.out += data
        self.out += b"\0" * (-len(self.out) % 4)

    def directory(self, name):
        parts = Path(name.lstrip("/")).parts
        for i in range(1, len(parts) + 1):
            self._entry("/".join(parts[:i]), stat.S_IFDIR | 0o755)

    def data(self, name, data, mode=0o644):
        self.directory(str(Path(name).parent))
        self._entry(name, stat.S_IFREG | mode, data)

    def host(self, path):
        """A host file (or folder, recursively) at its own path."""
        path = Path(path)
        parts = path.parts
        current = Path("/")
        for part in parts[1:-1]:  # links on the way are kept as links
            current = current / part
            if current.is_symlink():
                target = os.readlink(current)
                self.directory(str(current.parent))
                self._entry(str(current), stat.S_IFLNK | 0o777, target.encode())
                resolved = (current.parent / target).resolve()
                return self.host(resolved / path.relative_to(current))
        if path.is_symlink():
            target = os.readlink(path)
            self.directory(str(path.parent))
            self._entry(str(path), stat.S_IFLNK | 0o777, target.encode())
            return self.host((path.parent / target).resolve())
        if path.is_dir():
            self.directory(str(path))
            for child in sorted(path.iterdir()):
                self.host(child)
            return
        self.data(str(path), path.read_bytes(), stat.S_IMODE(path.stat().st_mode))

    def finish(self):
        self._entry("TRAILER!!!", 0)
        return bytes(self.out)


def build_initramfs(spec, release):
    archive = Cpio()
    archive.data("/init", INIT_SCRIPT.read_bytes(), 0o755)
    archive.host("/bin/busybox")
    executables = UDEV_PROGRAMS + list(spec.executables) + [argv[0] for _, argv in spec.programs]
    for executable in executables:
        if not Path(executable).exists():
            raise GuestError(f"{executable} is not there (scripts/setup.sh installs and builds it)")
        archive.host(executable)
        for lib in shared_libraries(executable):
            archive.host(lib)
    modules = module_files(release, spec.modules)
    for module in modules:
        archive.host(module)
    archive.data("/etc/kf/modules", "".join(f"{m}\n" for m in modules).encode())
    for rule in HOST_UDEV_RULES:
        archive.host(Path("/lib/udev/rules.d") / rule)
    for rule in spec.udev_rules:
        archive.data(f"/etc/udev/rules.d/{Path(rule).name}", Path(rule).read_bytes())
    for extra in spec.files:
        archive.host(extra)
    archive.data("/etc/passwd", PASSWD.encode())
    archive.data("/etc/group", GROUP.encode())
    if spec.seat_user:
        archive.data("/etc/kf/seat0", SEAT0.encode())
    run = "".join(f"kf_run {shlex.quote(name)} {shlex.join(argv)}\n" for name, argv in spec.programs)
    archive.data("/etc/kf/run.sh", run.encode())
    return archive.finish()


# --- running it -----------------------------------------------------------------------------

def qemu_command(spec, release, initramfs, console_path, hook_path, qmp_path):
    return ["qemu-system-x86_64", "-accel", "tcg", "-machine", "pc,vmport=off", "-cpu", "max", "-smp", "1",
            "-m", str(spec.memory_mb), "-nodefaults", "-display", "none", "-no-reboot",
            "-kernel", f"/boot/vmlinuz-{release}", "-initrd", str(initramfs),
            "-append", "console=ttyS0 quiet loglevel=3 panic=-1 sysrq_always_enabled rdinit=/init",
            "-serial", f"file:{console_path}",
            "-chardev", f"socket,id=hook,path={hook_path},server=on,wait=on", "-serial", "chardev:hook",
            "-qmp", f"unix:{qmp_path},server=on,wait=off", *spec.qemu_args]


class Qmp:
    def __init__(self, sock):
        self.sock = sock
        self.file = self.sock.makefile("rwb")
        self._read()  # greeting
        self.command({"execute": "qmp_capabilities"})

    def _read(self):
        line = self.file.readline()
        if not line:
            raise GuestError("QMP closed")
        return json.loads(line)

    def command(self, request):
        self.file.write(json.dumps(request).encode() + b"\n")
        self.file.flush()
        while True:
            answer = self._read()
            if "return" in answer or "error" in answer:
                return answer  # events in between are not asked for


def _connect(path, proc, timeout_s):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise GuestError(f"QEMU exited ({proc.returncode}) before its hook socket was there")
        if Path(path).exists():
            sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                sock.connect(str(path))
                return sock
            except OSError:
                sock.close()
        time.sleep(0.05)
    raise GuestError(f"QEMU made no hook socket in {timeout_s} s")


def run(spec, work_dir):
    work_dir = Path(work_dir)
    work_dir.mkdir(parents=True, exist_ok=True)
    result = GuestRun()
    try:
        release = kernel_release()
        result.kernel = release
        initramfs = work_dir / "initramfs.cpio"
        initramfs.write_bytes(build_initramfs(spec, release))
    except GuestError as error:
        result.failure = str(error)
        return result
    console_path, hook_path, qmp_path = work_dir / "console.log", work_dir / "hook.sock", work_dir / "qmp.sock"
    for stale in (hook_path, qmp_path):
        stale.unlink(missing_ok=True)
    command = qemu_command(spec, release, initramfs, console_path, hook_path, qmp_path)
    (work_dir / "qemu-command.txt").write_text(shlex.join(command) + "\n")
    start = time.monotonic()
    with open(work_dir / "qemu.log", "w") as qemu_log:
        proc = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=qemu_log, stderr=subprocess.STDOUT)
    try:
        _converse(spec, proc, hook_path, qmp_path, result, start)
    except GuestError as error:
        result.failure = str(error)
    except (OSError, ValueError) as error:  # the rig's own fault: still a failure with its reason
        result.failure = f"the host side of the rig failed: {error!r}"
    finally:
        _stop(proc)
        result.console = console_path.read_text(errors="replace") if console_path.exists() else ""
        qemu_text = "\n".join(line for line in (work_dir / "qemu.log").read_text(errors="replace").splitlines()
                              if "info: QEMU waiting for connection" not in line)
        if result.failure and qemu_text.strip():
            result.failure += f"\nQEMU said: {qemu_text.strip()[-2000:]}"
    return result


def _stop(proc):
    """Our own QEMU, by its process: it powers itself off after "done"; else it is ended."""
    try:
        proc.wait(10)
    except subprocess.TimeoutExpired:
        proc.terminate()
        try:
            proc.wait(5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def _converse(spec, proc, hook_path, qmp_path, result, start):
    hook = _connect(hook_path, proc, 30)
    qmp = Qmp(_connect(qmp_path, proc, 30))
    deadline = start + spec.timeout_s
    buffer = bytearray()

    def read_more():
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            _dump_blocked_tasks(qmp)
            raise GuestError(_stage_failure(result, f"the guest did not finish within {spec.timeout_s:.0f} s; "
                                                    "the tasks blocked in it are in console.log (sysrq w, l)"))
        hook.settimeout(min(remaining, 1.0))
        try:
            chunk = hook.recv(65536)
        except socket.timeout:
            if proc.poll() is not None:
                raise GuestError(_stage_failure(result, f"QEMU exited ({proc.returncode})"))
            return
        if not chunk:
            try:
                what = f"QEMU exited ({proc.wait(5)})"
            except subprocess.TimeoutExpired:
                what = "the guest closed its hook port"
            raise GuestError(_stage_failure(result, what))
        buffer.extend(chunk)

    def line():
        while b"\n" not in buffer:
            read_more()
        end = buffer.index(b"\n")
        text = buffer[:end].decode(errors="replace")
        del buffer[:end + 1]
        return text

    def exactly(size):
        while len(buffer) < size:
            read_more()
        data = bytes(buffer[:size])
        del buffer[:size]
        return data

    while True:
        text = line()
        word, _, rest = text.partition(" ")
        if word == "hello":
            result.kernel = rest
            result.boot_s = time.monotonic() - start
        elif word == "log":
            result.logs.append(rest)
        elif word == "error":
            raise GuestError(f"the guest failed: {rest}")
        elif word == "qmp":
            try:
                answer = qmp.command(json.loads(rest))
            except json.JSONDecodeError as error:
                answer = {"error": {"class": "GuestRequest", "desc": f"the host could not read the request: {error}"}}
            result.qmp_log.append((rest, answer))
            hook.sendall(b"qmp " + json.dumps(answer).encode() + b"\n")
        elif word == "host":
            name, _, argument = rest.partition(" ")
            handler = spec.hooks.get(name)
            reply = handler(argument) if handler else f"error no host hook {name}"
            hook.sendall(b"host " + reply.replace("\n", " ").encode() + b"\n")
        elif word == "file":
            name, size = rest.rsplit(" ", 1)
            result.files[name] = exactly(int(size))
        elif word == "exit":
            name, status = rest.rsplit(" ", 1)
            result.exits[name] = int(status)
        elif word == "done":
            result.wall_s = time.monotonic() - start
            return
        elif text.strip():
            result.logs.append(f"(unknown line from the guest) {text}")


def _dump_blocked_tasks(qmp, settle_s=3.0):
    """A guest that hangs: where. SysRq 8 (every kernel message to the console, which runs at
    loglevel 3), then w (the tasks in uninterruptible sleep, with their stacks) and l (what the
    CPU runs: a realtime thread that spins), typed on the guest's keyboard through QMP; the
    kernel writes them to the console before QEMU is stopped."""
    for key in ("8", "w", "l"):
        keys = [{"type": "qcode", "data": name} for name in ("alt", "sysrq", key)]
        qmp.command({"execute": "send-key", "arguments": {"keys": keys}})
    time.sleep(settle_s)


def _stage_failure(result, what):
    if not result.boot_s:
        return f"{what}: the guest did not boot (no hello from its /init)"
    stage = result.logs[-1] if result.logs else "before any log line"
    return f"{what}; last step: {stage}"
