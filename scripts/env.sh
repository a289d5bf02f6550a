# Sourced by the scripts: what headless sclang needs, and the Debian python with numpy.
export QT_QPA_PLATFORM=offscreen
export QTWEBENGINE_DISABLE_SANDBOX=1
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/kf-xdg-$(id -u)}"
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
KF_PYTHON=/usr/bin/python3
export PYTHONPATH="$(pwd)/python${PYTHONPATH:+:$PYTHONPATH}"
