#!/usr/bin/env bash
# Installs moas-gui (scripts/setup.sh) and starts the server window on an example
# station whose switches are the built-in emulator (no hardware needed).
# With no display (a server over ssh), it runs the same server headless instead.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
example="${1:-examples/big-station.moas}"
shift || true
if [ "$(uname)" = "Linux" ] && [ -z "${DISPLAY:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ]; then
    echo "run-example: no display; running the server headless (Ctrl+C stops it)" >&2
    exec .venv/bin/moas-server --headless "$example" "$@"
fi
exec .venv/bin/moas-server "$example" "$@"
