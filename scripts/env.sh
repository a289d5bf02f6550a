# Sourced by the scripts: what headless sclang needs, and the Debian python with numpy.
export QT_QPA_PLATFORM=offscreen
export QTWEBENGINE_DISABLE_SANDBOX=1
# sclang starts Qt WebEngine, which no headless run shows a page in: without its zygote processes
# and GPU process a start costs 0.9 CPU-s instead of 1.1 (python/kfharness/sclang.py environment).
export QTWEBENGINE_CHROMIUM_FLAGS="${QTWEBENGINE_CHROMIUM_FLAGS:---no-zygote --disable-gpu}"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/kf-xdg-$(id -u)}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
KF_PYTHON=/usr/bin/python3
export PYTHONPATH="$(pwd)/python${PYTHONPATH:+:$PYTHONPATH}"
