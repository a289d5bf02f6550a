# Sourced by the scripts: what headless sclang needs, and the Debian python with numpy.
export QT_QPA_PLATFORM=offscreen
export QTWEBENGINE_DISABLE_SANDBOX=1
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/kf-xdg-$(id -u)}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
KF_PYTHON=/usr/bin/python3
export PYTHONPATH="$(pwd)/python${PYTHONPATH:+:$PYTHONPATH}"
# NumPy asks for transparent huge pages on its large arrays (madvise), and the kernel's khugepaged
# then collapses them, 35 ms at a time without yielding its CPU on a kernel that preempts only at
# its own points (this machine's; Debian's by default): the realtime threads woken there (JACK's,
# scsynth's audio thread, the device threads) waited the whole time, every 33 ms while the main
# job's Python rendered beside a study (perf sched timehist, ARCHITECTURE.md).
export NUMPY_MADVISE_HUGEPAGE=0
# Ninja builds a new build folder (setup.sh installs it; an existing folder keeps the generator it
# was configured with, as CMake ignores CMAKE_GENERATOR then): build/ --all from nothing took
# 351 CPU-s and 177 s with it against 368 CPU-s and 188 s with Make, which starts a cmake for each
# target's dependencies and progress (-j2, one after the other, at 6a5c03f).
if command -v ninja >/dev/null; then export CMAKE_GENERATOR="${CMAKE_GENERATOR:-Ninja}"; fi
