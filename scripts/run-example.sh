#!/usr/bin/env bash
# Installs moas-gui (scripts/setup.sh) and starts the server window on an example
# station whose switches are the built-in emulator (no hardware needed); the
# example's serial rotators get emulated controllers.  With no display (a server
# over ssh), it runs the same server headless instead.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
example="${1:-examples/big-station.moas}"
shift || true
emulators=$(.venv/bin/python scripts/example_rotators.py "$example")
cleanup() { for pid in $emulators; do kill "$pid" 2>/dev/null || true; done; }
trap cleanup EXIT
if [ "$(uname)" = "Linux" ] && [ -z "${DISPLAY:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ]; then
    echo "run-example: no display; running the server headless (Ctrl+C stops it)" >&2
    .venv/bin/moas-server --headless "$example" "$@"
else
    .venv/bin/moas-server "$example" "$@"
fi
