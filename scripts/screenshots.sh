#!/usr/bin/env bash
# Screenshots for the docs, on a 1024x600 screen (a small station laptop) and at a
# phone's size: the server window and its tray menu (docs/server.md), then the client
# window's states (scripts/screenshot_client.py, docs/client.md) and the web page's at
# 1024x600 and 390x844 (scripts/screenshot_web.py, docs/web-client.md), and what a phone
# shows when pairing (scripts/screenshot_pairing.py, docs/security.md).  Look at them.
#
# Runs everything on a virtual X display of its own (Xvfb), with a small window
# manager (openbox, for title bars, when installed) and a system tray (trayer):
#   1. starts the server window on examples/big-station.moas (built-in emulated
#      switches), plays N1MM Logger on 127.0.0.1 so antenna changes are logged,
#      and grabs docs/images/server-window.png;
#   2. right-clicks the tray icon (a real click, with xdotool), grabs the corner
#      with the menu as docs/images/server-tray-menu.png, then chooses Exit.
#
# Only this script needs these Debian packages (scripts/setup.sh does not):
#   apt-get install -y --no-install-recommends xvfb xauth trayer imagemagick \
#       xdotool x11-utils openbox
# plus the Qt X11 libraries that scripts/setup.sh installs for the window.
#
# Usage: scripts/screenshots.sh [OUTPUT-FOLDER]   (default docs/images)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
out="${1:-docs/images}"
python="$root/.venv/bin/python"
helper="$root/scripts/screenshot_tray.py"
width=1024
height=600

missing=()
for tool in Xvfb xauth xdpyinfo trayer import convert display xdotool; do
    command -v "$tool" >/dev/null || missing+=("$tool")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "screenshots: missing ${missing[*]}; install them with:" >&2
    echo "  apt-get install -y --no-install-recommends xvfb xauth trayer imagemagick xdotool x11-utils openbox" >&2
    exit 1
fi
[ -x "$python" ] || { echo "screenshots: no $python; run scripts/setup.sh first" >&2; exit 1; }
mkdir -p "$out"

work=$(mktemp -d /tmp/moas-screenshots.XXXXXX)
pids=()
cleanup() {
    local pid
    for ((i = ${#pids[@]} - 1; i >= 0; i--)); do
        pid=${pids[i]}
        kill "$pid" 2>/dev/null || true
        for _ in 1 2 3 4 5 6 7 8 9 10; do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.2
        done
        kill -9 "$pid" 2>/dev/null || true
    done
    rm -rf "$work"
}
trap cleanup EXIT

wait_for() {  # wait_for SECONDS COMMAND...: until COMMAND succeeds
    local end=$((SECONDS + $1))
    shift
    until "$@" >/dev/null 2>&1; do
        [ $SECONDS -lt $end ] || return 1
        sleep 0.2
    done
}

# --- a display of our own, with a cookie -------------------------------------------
number=90
while [ -e "/tmp/.X11-unix/X$number" ] || [ -e "/tmp/.X$number-lock" ]; do
    number=$((number + 1))
done
export DISPLAY=":$number"
export XAUTHORITY="$work/Xauthority"
touch "$XAUTHORITY"
xauth -q -f "$XAUTHORITY" add "$DISPLAY" . "$(od -An -N16 -tx1 /dev/urandom | tr -d ' \n')"
Xvfb "$DISPLAY" -screen 0 "${width}x${height}x24" -nolisten tcp -auth "$XAUTHORITY" \
    >"$work/xvfb.log" 2>&1 &
pids+=($!)
wait_for 10 xdpyinfo || {
    echo "screenshots: Xvfb did not start:" >&2
    cat "$work/xvfb.log" >&2
    exit 1
}

# A plain desktop colour, a window manager for title bars, a tray at the bottom right.
convert -size "${width}x${height}" "xc:#3b5b78" "$work/desktop.png"
display -window root "$work/desktop.png" || true  # sets the background; exits 1 all the same
if command -v openbox >/dev/null; then
    openbox >"$work/openbox.log" 2>&1 &
    pids+=($!)
    sleep 1
fi
trayer --edge bottom --align right --widthtype pixel --width 120 --heighttype pixel --height 30 \
    --transparent false --tint 0xdcdcdc --SetDockType true --SetPartialStrut true \
    >"$work/trayer.log" 2>&1 &
pids+=($!)
wait_for 10 xdotool search --onlyvisible --class trayer

# --- the server window ----------------------------------------------------------------
# The file's own ports when they are free (they show in the log), else any free ones.
udp=$("$python" "$helper" free-port udp 12060)
tcp=$("$python" "$helper" free-port tcp 12059)
mkdir -p "$work/config"
XDG_CONFIG_HOME="$work/config" XDG_STATE_HOME="$work/state" XDG_DATA_HOME="$work/data" QT_QPA_PLATFORM=xcb \
    "$python" "$helper" serve examples/big-station.moas --bind 127.0.0.1 \
    --tcp-port "$tcp" --udp-port "$udp" --no-rotator-program --new-instance \
    >"$work/server.log" 2>&1 &
server=$!
pids+=($server)
if ! wait_for 30 xdotool search --onlyvisible --name "big-station.moas - MOAS Server"; then
    echo "screenshots: the server window did not open:" >&2
    cat "$work/server.log" >&2
    exit 1
fi
window=$(xdotool search --onlyvisible --name "big-station.moas - MOAS Server" | head -1)
xdotool windowsize "$window" 960 400
xdotool windowmove "$window" 24 24
sleep 1.5                          # both emulated switches answer
"$python" "$helper" client "$tcp" 60 &   # a button box connects
pids+=($!)
"$python" "$helper" n1mm "$udp"    # the operator tunes radio 1 across a few bands
sleep 1
import -frame -window "$window" -strip "$out/server-window.png"
echo "screenshots: wrote $out/server-window.png"

# --- the tray icon's menu, opened with a real right click --------------------------------
read -r tx ty tw th < <("$python" "$helper" geometry-class trayer)
xdotool mousemove "$((tx + tw - 12))" "$((ty + th / 2))" click 3   # the icon: right end of the tray
wait_for 10 "$python" "$helper" tray-menu || { echo "screenshots: the tray menu did not open" >&2; exit 1; }
read -r mx my mw mh < <("$python" "$helper" tray-menu)
xdotool mousemove "$((mx + mw / 2))" "$((my + mh / 2))"   # point at Stop Switches, as a user does
sleep 0.5
left=$((mx - 120))
top=$((my - 40))
import -window root -crop "$((width - left))x$((height - top))+$left+$top" +repage -strip \
    "$out/server-tray-menu.png"
echo "screenshots: wrote $out/server-tray-menu.png"

# Exit, the menu's last item, as a user ends the server.
xdotool mousemove "$((mx + mw / 2))" "$((my + mh - 10))" click 1
for _ in $(seq 1 50); do
    kill -0 "$server" 2>/dev/null || break
    sleep 0.2
done
if kill -0 "$server" 2>/dev/null; then
    echo "screenshots: the server did not exit from its tray menu; stopping it" >&2
    exit 1
fi
echo "screenshots: the server exited from its tray menu"

# --- the client window's states and the web page's, 1024x600 and a phone ------------------
XDG_CONFIG_HOME="$work/config" XDG_STATE_HOME="$work/state" XDG_DATA_HOME="$work/data" QT_QPA_PLATFORM=xcb \
    "$python" scripts/screenshot_client.py "$out"
"$python" scripts/screenshot_web.py "$out"
"$python" scripts/screenshot_pairing.py "$out"
