#!/usr/bin/env bash
# Installs moas-gui (scripts/setup.sh) and starts the server window on an example
# station whose switches are the built-in emulator (no hardware needed); the
# example's serial rotators get emulated controllers, linked in a private directory
# of this user's (mode 700, the same every run, so that the example's copy naming
# them is the same file with the same content every run: Recent Files lists it and
# its saved state comes back).  An example with nothing to emulate is opened as it
# is, so every message names the example itself.  The server listens on this computer only
# (127.0.0.1) unless --bind or --udp-bind is given.  When no display can be opened
# (a server over ssh, or a DISPLAY that does not answer), it runs the same server
# headless instead.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
example="${1:-examples/big-station.moas}"
shift || true
private="${XDG_STATE_HOME:-$HOME/.local/state}/moas-gui/example-run"
mkdir -p "$private" && chmod 700 "$private"  # this user's alone
emulators=$(.venv/bin/python scripts/example_rotators.py "$example" "$private")
cleanup() {
    for pid in $emulators; do kill "$pid" 2>/dev/null || true; done
    find "$private" -maxdepth 1 -type l -delete 2>/dev/null || true  # the emulators' links
}
trap cleanup EXIT
opened="$private/$(basename "$example")"
if cmp -s "$opened" "$example"; then
    opened="$example"  # nothing rewritten: the example itself (and its name in messages)
fi
bind=()
case " $* " in *" --bind"*) ;; *) bind+=(--bind 127.0.0.1) ;; esac
case " $* " in *" --udp-bind"*) ;; *) bind+=(--udp-bind 127.0.0.1) ;; esac
if problem=$(.venv/bin/python -m moas_gui.ui.display); then
    .venv/bin/moas-server "$opened" "${bind[@]}" "$@"
else
    echo "run-example: $problem; running the server headless (Ctrl+C stops it)" >&2
    .venv/bin/moas-server --headless "$opened" "${bind[@]}" "$@"
fi
