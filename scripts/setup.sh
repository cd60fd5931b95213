#!/usr/bin/env bash
# Sets up everything moas-gui needs on a Debian or Ubuntu machine (and, without the
# Debian packages, on macOS; on Windows see README.md):
#   scripts/setup.sh          the server (Qt's system libraries when root, a venv in .venv)
#   scripts/setup.sh --test   also what the test suite needs (Hamlib, socat, xvfb, test extra)
set -euo pipefail
cd "$(dirname "$0")/.."
want_test=0
[ "${1:-}" = "--test" ] && want_test=1

apt_pkgs="libegl1 libgl1 libfontconfig1 libxkbcommon0 libdbus-1-3 libglib2.0-0 fonts-dejavu-core"
# what a real window on X11 needs beyond that
apt_pkgs="$apt_pkgs libxcb-cursor0 libxcb-icccm4 libxcb-keysyms1 libxcb-image0 libxcb-randr0"
apt_pkgs="$apt_pkgs libxcb-render-util0 libxcb-shape0 libxcb-xkb1 libxkbcommon-x11-0"
if [ "$want_test" = 1 ]; then
    apt_pkgs="$apt_pkgs libhamlib-utils socat shared-mime-info xvfb xauth trayer chromium chromium-driver openssl"
fi
# as root, or with MOAS_SETUP_SUDO=1 through sudo (a CI runner: passwordless sudo)
as_root=""
[ "$(id -u)" = 0 ] || { [ "${MOAS_SETUP_SUDO:-}" = 1 ] && as_root="sudo"; }
if { [ "$(id -u)" = 0 ] || [ -n "$as_root" ]; } && command -v apt-get >/dev/null 2>&1; then
    missing=""
    for p in $apt_pkgs; do
        dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
    done
    if [ -n "$missing" ]; then
        echo "setup: installing Debian packages:$missing" >&2
        $as_root apt-get update -qq >/dev/null
        $as_root env DEBIAN_FRONTEND=noninteractive \
            apt-get install -y -qq --no-install-recommends $missing >/dev/null
    fi
fi

py="${PYTHON:-python3}"
[ -x .venv/bin/python ] || "$py" -m venv .venv
extra=""
[ "$want_test" = 1 ] && extra="[test]"
stamp=".venv/.installed$extra"
# what the test set-up installed includes the plain one
if [ -z "$extra" ] && [ ! -f "$stamp" ] && [ -f ".venv/.installed[test]" ]; then
    stamp=".venv/.installed[test]"
fi
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ]; then
    .venv/bin/python -m pip install -q --disable-pip-version-check -e ".$extra"
    touch "$stamp"
fi
# an editable install compiles nothing: compile the package once here, not in every
# process that first imports it (servers, emulators and test workers start many)
.venv/bin/python -m compileall -q -j 0 moas_gui >/dev/null
if [ "$want_test" = 1 ]; then
    # pytest compiles each test module in its own way (assertions rewritten): once here,
    # not once in each of the suite's parallel workers at the same time
    .venv/bin/python -m pytest -q -p no:cacheprovider -n 0 --collect-only >/dev/null
fi
# The Raspberry Pi check under emulation (scripts/pi-check.sh: arm64 Debian roots, the
# wheel installed in them, the station served there; minutes, and root): only when asked,
# so `MOAS_PI_CHECK=1 bash .ci/run` runs it before the suite and fails with it.
if [ "$want_test" = 1 ] && [ "${MOAS_PI_CHECK:-}" = 1 ]; then
    bash scripts/pi-check.sh
fi
