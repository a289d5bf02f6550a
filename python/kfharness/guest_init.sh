#!/bin/busybox sh
# The QEMU guest's /init (python/kfharness/guest.py puts it in the initramfs): mounts the kernel's
# file systems, loads the modules the run asked for, starts systemd-udevd with the rules given,
# runs the test programs of /etc/kf/run.sh and sends their result files and exit statuses to the
# host over the second serial port (/dev/ttyS1, the host hook; protocol in guest.py), then powers
# off. Whatever goes wrong is sent as "error <reason>" and ends the run: the host fails with it.
/bin/busybox --install -s /bin
export PATH=/bin:/sbin:/usr/bin:/usr/sbin
mkdir -p /proc /sys /dev /run /tmp
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
mount -t tmpfs tmpfs /run
# /tmp stays the initramfs's own (writable) folder: a tmpfs over it would hide the programs of a
# clone under /tmp, which the initramfs holds at their host paths.

exec 3<>/dev/ttyS1
stty -F /dev/ttyS1 raw -echo 115200
say() { printf '%s\n' "$*" >&3; }
fail() {
	say "error $*"
	poweroff -f
}
say "hello $(uname -r)"

# Modules, dependencies first (guest.py ordered them from the kernel's modules.dep).
while read -r module; do
	[ -n "$module" ] || continue
	message=$(insmod "$module" 2>&1) || fail "insmod $module: $message"
done < /etc/kf/modules
say "log modules loaded: $(wc -l < /etc/kf/modules)"

# The user at the seat: what systemd-logind writes for udev's uaccess builtin (the seat's
# active session and its user), written here as logind would, since no logind runs.
if [ -f /etc/kf/seat0 ]; then
	mkdir -p /run/systemd/seats
	cp /etc/kf/seat0 /run/systemd/seats/seat0
fi

/lib/systemd/systemd-udevd --daemon --resolve-names=late || fail "systemd-udevd did not start"
udevadm trigger --action=add --type=subsystems
udevadm trigger --action=add --type=devices
udevadm settle --timeout=60 || fail "udevadm settle timed out"
say "log udev settled"

mkdir -p /results
export KF_GUEST_RESULTS=/results
# kf_run NAME PROGRAM ARGS...: runs it, its output on the console, its status to the host.
kf_run() {
	name=$1
	shift
	say "log running $name"
	"$@"
	say "exit $name $?"
}
. /etc/kf/run.sh

for file in /results/*; do
	[ -f "$file" ] || continue
	say "file ${file##*/} $(wc -c < "$file")"
	cat "$file" >&3
done
say "done"
sleep 1
poweroff -f
