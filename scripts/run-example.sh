#!/usr/bin/env bash
# Installs moas-gui (scripts/setup.sh) and starts the server window on an example
# station whose switches are the built-in emulator (no hardware needed); the
# example's serial rotators get emulated controllers, linked in a private directory
# of this user's (mode 700), and the server is told where they are with
# --rotator-port ID=LINK: the example itself is opened, unchanged, so Recent Files
# and every message name it and its saved state comes back at the next run.  The
# server listens on this computer only
# (127.0.0.1) unless --bind or --udp-bind is given.  The browser page is served too
# (on port 8080 unless the options or the file name one), and the page's address and
# the desktop client's command are printed before the server starts.  When no display can be opened
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
opened="$example"  # the example itself, never a copy
moved=()
while read -r line; do
    [ -n "$line" ] && moved+=(--rotator-port "$line")
done <"$private/rotator-ports"
bind=()
case " $* " in *" --bind"*) ;; *) bind+=(--bind 127.0.0.1) ;; esac
case " $* " in *" --udp-bind"*) ;; *) bind+=(--udp-bind 127.0.0.1) ;; esac
web=()
while read -r line; do
    [ -n "$line" ] && web+=("$line")
done < <(.venv/bin/python scripts/example_addresses.py "$opened" "${bind[@]}" "$@")
if problem=$(.venv/bin/python -m moas_gui.ui.display); then
    .venv/bin/moas-server "$opened" "${bind[@]}" ${web[@]+"${web[@]}"} ${moved[@]+"${moved[@]}"} "$@"
else
    echo "run-example: $problem; running the server headless (Ctrl+C stops it)" >&2
    .venv/bin/moas-server --headless "$opened" "${bind[@]}" ${web[@]+"${web[@]}"} \
        ${moved[@]+"${moved[@]}"} "$@"
fi
