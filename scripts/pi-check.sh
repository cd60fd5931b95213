#!/usr/bin/env bash
# A Raspberry Pi at the tower, tried under emulation on this machine (docs/platforms.md,
# "A Raspberry Pi").  For each release (Debian 12 bookworm and Debian 13 trixie, the bases
# of Raspberry Pi OS) it builds once an arm64 Debian root from Debian's archive and keeps it
# in the cache; then, on every run:
#
#   * builds this checkout's wheel and installs it in each root with `pipx install WHEEL`
#     as the user `pi` (in `dialout`), as docs/platforms.md tells a Pi's owner, every
#     dependency from the package index; on this machine the same wheel goes into a fresh
#     virtual environment with pip, for the figures beside it;
#   * runs scripts/pi_probe.py for this machine and for each root: `moas-server --check`
#     and `--plan` on every installed example; the headless server on small-station.moas
#     against moas-emulator on a socat pseudo-terminal pair; a client's hello; band changes
#     from N1MM Logger datagrams answered with relay bytes on the cable; RSS, CPU and no Qt
#     library mapped; `--install-service` and `systemd-analyze verify --user` on the unit;
#   * in the bookworm root the window server too (offscreen, with the oldest Qt pip gives
#     bookworm), answering a client;
#   * prints a table of the figures (this machine, each root, and the ratio) and exits 1
#     if anything failed.
#
# The arm64 programs run through qemu-aarch64 registered with binfmt_misc (mounted and
# registered here if it is not: root with CAP_SYS_ADMIN), inside `chroot` in a private
# mount namespace; where binfmt_misc cannot be had, the root is built with
# `debootstrap --foreign` and everything runs under `proot -q qemu-aarch64-static`.
# Everything emulated runs under `nice -n 19`, one job at a time.  Speed under emulation
# is not a Pi's speed: figures are reported as measured and as a ratio to this machine.
#
# Needs root and the checkout's .venv (scripts/setup.sh --test).  Takes minutes (the first
# run, building the roots, longer).  The suite runs it only when MOAS_PI_CHECK=1
# (tests/rules/test_pi_check.py).
#
#   bash scripts/pi-check.sh                 # both releases
#   MOAS_PI_RELEASES=trixie bash scripts/pi-check.sh
#
# Settings: MOAS_PI_ROOTS (where the roots are kept, default
# ${XDG_CACHE_HOME:-~/.cache}/moas-gui/pi-roots), MOAS_PI_RELEASES, MOAS_PI_MIRROR (a
# Debian archive, default http://deb.debian.org/debian), MOAS_PI_EMULATION (binfmt or
# proot; default: binfmt where it can be had), MOAS_PI_TESTS (test paths, e.g. "tests/ui
# tests/client" or "tests": run the suite's fast tier on them in the bookworm root too,
# with the PySide6 pip gave it; long under emulation).  The output is kept in
# MOAS_PI_ROOTS/pi-check-<time>.log.
set -euo pipefail
CHECKOUT=$(cd "$(dirname "$0")/.." && pwd)
ROOTS=${MOAS_PI_ROOTS:-${XDG_CACHE_HOME:-$HOME/.cache}/moas-gui/pi-roots}
RELEASES=${MOAS_PI_RELEASES:-bookworm trixie}
MIRROR=${MOAS_PI_MIRROR:-http://deb.debian.org/debian}
# pipx as a Pi owner gets it; systemd for systemd-analyze; the libraries Qt's wheels need
# (Raspberry Pi OS with a desktop has them) for the window server
PACKAGES=pipx,ca-certificates,systemd,libegl1,libgl1,libfontconfig1,libxkbcommon0,libdbus-1-3,libglib2.0-0
NICE=(nice -n 19)
PYTHON=$CHECKOUT/.venv/bin/python

installed() {  # what a virtual environment holds of the packages that matter here
    find "$1" -maxdepth 5 -type d -name '*.dist-info' -printf '%f\n' \
        | grep -Ei '^(pyside6_essentials|shiboken6|aiohttp|pyserial|qasync|cryptography|moas_gui)-' \
        | sed 's/\.dist-info$//' | sort | tr '\n' ' '
}

add_pi() {  # the Pi's first user, pi (1000), in dialout, as Raspberry Pi OS makes it
    # (written here: trixie's smallest root has no useradd)
    grep -q '^pi:' "$1/etc/passwd" && return 0
    echo 'pi:x:1000:1000:pi:/home/pi:/bin/bash' >> "$1/etc/passwd"
    echo 'pi:x:1000:' >> "$1/etc/group"
    [ ! -e "$1/etc/shadow" ] || echo 'pi:!:20000:0:99999:7:::' >> "$1/etc/shadow"
    sed -i -e '/^dialout:/ { s/:$/:pi/; t; s/$/,pi/ }' "$1/etc/group"
    mkdir -p "$1/home/pi"
    chown 1000:1000 "$1/home/pi"
}

debian_version() {  # a package's version in a root, from dpkg's status file
    awk -v p="$2" '$1 == "Package:" { hit = ($2 == p) } hit && $1 == "Version:" { print $2; exit }' \
        "$1/var/lib/dpkg/status"
}

# (Everything is in functions, read whole before anything runs: the script may be edited
# while a long run of it goes on.)

# --- inside a private mount namespace: one release's install and probe ----------------
in_root() {
    release=$2 root=$3 wheel=$4 mode=$5 out=$6
    if [ "$mode" = binfmt ]; then
        mount --rbind /dev "$root/dev"
        mount -t proc proc "$root/proc"
        mount -t sysfs sysfs "$root/sys"
    fi
    as_pi() {
        local env=(/usr/bin/env -i HOME=/home/pi LANG=C.UTF-8
                   PATH=/home/pi/.local/bin:/usr/local/bin:/usr/bin:/bin
                   PIP_CERT=/etc/ssl/certs/pi-check-host.crt)
        if [ "$mode" = binfmt ]; then
            "${NICE[@]}" chroot --userspec=pi:pi "$root" "${env[@]}" "$@"
        else
            "${NICE[@]}" proot -q qemu-aarch64-static -r "$root" -b /dev -b /proc -b /sys \
                -w /home/pi "${env[@]}" "$@"
        fi
    }
    echo "== $release: pipx install $(basename "$wheel") (as pi, packages from the index)"
    cached=$(du -sm "$root/home/pi/.cache/pip" 2>/dev/null | cut -f1 || true)
    started=$(date +%s.%N)
    as_pi pipx install "/home/pi/$(basename "$wheel")" > "$out.install" 2>&1 \
        || { cat "$out.install"; echo "FAIL [$release]: pipx install"; exit 1; }
    ended=$(date +%s.%N)
    awk "BEGIN { printf \"  installed in %.0f s\\n\", $ended - $started }"
    venv=$(find "$root/home/pi/.local" -maxdepth 6 -type d -path '*/venvs/moas-gui' | head -n 1)
    examples=$(find "$venv" -maxdepth 6 -type d -path '*site-packages/moas_gui/examples' | head -n 1)
    echo "  pip's cache before: ${cached:-0} MB; installed: $(installed "$venv")"
    awk "BEGIN { printf \"INSTALL {\\\"install_s\\\": %.1f}\\n\", $ended - $started }" >> "$out.figures"
    "${NICE[@]}" "$PYTHON" "$CHECKOUT/scripts/pi_probe.py" --label "$release" --root "$root" \
        --mode "${mode/binfmt/chroot}" --bin /home/pi/.local/bin --examples "${examples#"$root"}" \
        --emulator "$CHECKOUT/.venv/bin/moas-emulator" --timeout 300 \
        --window | tee -a "$out.figures"
    [ "${PIPESTATUS[0]}" = 0 ] || exit 1
    if [ -n "${MOAS_PI_TESTS:-}" ] && [ "$release" = bookworm ]; then
        # the suite's fast tier on the oldest Qt a Pi gets, under emulation (long)
        echo "== $release: the suite's fast tier ($MOAS_PI_TESTS) on what pip gave the root"
        rm -rf "$root/home/pi/src" "$root/home/pi/tier"
        mkdir "$root/home/pi/src"
        tar -C "$CHECKOUT" --exclude=./.venv --exclude=./.git --exclude='*/__pycache__' \
            --exclude=./.mypy_cache --exclude=./build --exclude=./dist -c . \
            | tar -x -C "$root/home/pi/src"
        chown -R --reference="$root/home/pi" "$root/home/pi/src"
        started=$(date +%s)
        as_pi python3 -m venv /home/pi/tier
        as_pi /home/pi/tier/bin/python -m pip install -q "/home/pi/$(basename "$wheel")" \
            pytest pytest-qt pytest-asyncio pytest-timeout pytest-xdist hypothesis \
            keyrings.alt adif-io packaging > "$out.tier" 2>&1 || { cat "$out.tier"; exit 1; }
        echo "  $(installed "$root/home/pi/tier"), in $(( $(date +%s) - started )) s"
        started=$(date +%s)
        # shellcheck disable=SC2086  # MOAS_PI_TESTS is a list of paths
        as_pi /usr/bin/env QT_QPA_PLATFORM=offscreen XDG_RUNTIME_DIR=/tmp/pi-check/run \
            sh -c "cd /home/pi/src && exec /home/pi/tier/bin/python -m pytest -q \
                   -p no:cacheprovider -n 0 -m 'not realtime' --timeout 1200 $MOAS_PI_TESTS" \
            | tail -n 15 || exit 1
        echo "  (the tests ran $(( $(date +%s) - started )) s under emulation)"
    fi
    exit 0
}

# --- the run ----------------------------------------------------------------------------
main() {
if [ "$(id -u)" != 0 ]; then
    echo "pi-check: needs root (chroot, mounts, binfmt_misc)" >&2
    exit 2
fi
if [ ! -x "$PYTHON" ]; then
    echo "pi-check: no $PYTHON: run scripts/setup.sh --test first" >&2
    exit 2
fi
mkdir -p "$ROOTS"
LOG=$ROOTS/pi-check-$(date -u +%Y%m%dT%H%M%SZ).log
exec > >(tee "$LOG") 2>&1
echo "pi-check: $(date -u '+%F %T') UTC, $(uname -m), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "  log: $LOG"

missing=()
for tool in mmdebstrap:mmdebstrap debootstrap:debootstrap qemu-aarch64-static:qemu-user-static \
            update-binfmts:binfmt-support proot:proot socat:socat systemd-analyze:systemd; do
    command -v "${tool%%:*}" > /dev/null || missing+=("${tool#*:}")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "== installing Debian's ${missing[*]}"
    apt-get update -q > /dev/null
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}" > /dev/null
fi

# binfmt_misc: mounted and qemu registered, or proot
mode=${MOAS_PI_EMULATION:-}
if [ -z "$mode" ]; then
    binfmt=/proc/sys/fs/binfmt_misc
    [ -e $binfmt/register ] || mount -t binfmt_misc binfmt_misc $binfmt 2> /dev/null || true
    [ -e $binfmt/qemu-aarch64 ] || update-binfmts --enable qemu-aarch64 2> /dev/null || true
    if grep -qs '^enabled' $binfmt/qemu-aarch64; then mode=binfmt; else mode=proot; fi
fi
echo "  emulation: $mode ($(qemu-aarch64-static --version | head -n 1))"

failed=0
work=$(mktemp -d /tmp/pi-check.XXXXXX)
trap 'rm -rf "$work"' EXIT

echo "== the wheel, built from $CHECKOUT"
"$PYTHON" -m build --wheel --no-isolation --outdir "$work/dist" "$CHECKOUT" > "$work/build.log" 2>&1 \
    || { cat "$work/build.log"; echo "FAIL: the wheel"; exit 1; }
wheel=$(ls "$work"/dist/*.whl)
echo "  $(basename "$wheel") ($(du -k "$wheel" | cut -f1) kB)"

echo "== this machine: pip install the wheel into a fresh virtual environment"
started=$(date +%s.%N)
"${NICE[@]}" "$PYTHON" -m venv --without-pip "$work/host-venv" 2> /dev/null \
    || "${NICE[@]}" python3 -m venv --without-pip "$work/host-venv"
"${NICE[@]}" "$work/host-venv/bin/python" -m ensurepip > /dev/null
"${NICE[@]}" "$work/host-venv/bin/python" -m pip install -q "$wheel" > "$work/host-install.log" 2>&1 \
    || { cat "$work/host-install.log"; echo "FAIL [host]: pip install"; exit 1; }
ended=$(date +%s.%N)
awk "BEGIN { printf \"INSTALL {\\\"install_s\\\": %.1f}\\n\", $ended - $started }" > "$work/host.figures"
examples=$(ls -d "$work"/host-venv/lib/python3*/site-packages/moas_gui/examples)
echo "  Python $("$work/host-venv/bin/python" -c 'import sys; print(sys.version.split()[0])'); installed: $(installed "$work/host-venv")"
"${NICE[@]}" "$PYTHON" "$CHECKOUT/scripts/pi_probe.py" --label host --bin "$work/host-venv/bin" \
    --examples "$examples" --emulator "$CHECKOUT/.venv/bin/moas-emulator" \
    --work "$work/host" --window | tee -a "$work/host.figures" \
    || failed=1

for release in $RELEASES; do
    root=$ROOTS/$release
    if [ ! -e "$root/.pi-check-root" ]; then
        echo "== $release: building an arm64 root from $MIRROR (once; kept in $ROOTS)"
        rm -rf "$root.tmp"
        started=$(date +%s)
        if [ "$mode" = binfmt ]; then
            "${NICE[@]}" mmdebstrap --quiet --variant=apt --architectures=arm64 \
                --include="$PACKAGES" "$release" "$root.tmp" "$MIRROR" \
                || { echo "FAIL [$release]: mmdebstrap"; failed=1; continue; }
        else
            "${NICE[@]}" debootstrap --foreign --arch=arm64 --variant=minbase \
                --include="$PACKAGES" "$release" "$root.tmp" "$MIRROR" > "$work/debootstrap.log" \
                && "${NICE[@]}" proot -0 -q qemu-aarch64-static -r "$root.tmp" -b /dev -b /proc \
                    /debootstrap/debootstrap --second-stage >> "$work/debootstrap.log" \
                || { tail -n 20 "$work/debootstrap.log"; echo "FAIL [$release]: debootstrap"; failed=1; continue; }
        fi
        touch "$root.tmp/.pi-check-root"
        mv "$root.tmp" "$root"
        echo "  built in $(( $(date +%s) - started )) s, $(du -sm "$root" | cut -f1) MB"
    fi
    echo "== $release: $(sed -n 's/^PRETTY_NAME=//p' "$root/etc/os-release" | tr -d '"') arm64," \
        "glibc $(debian_version "$root" libc6), python3 $(debian_version "$root" python3)," \
        "pipx $(debian_version "$root" pipx), systemd $(debian_version "$root" systemd)"
    # the Pi's owner: a user in dialout, with this network's name server and certificate
    # authorities (an HTTPS proxy with an authority of its own is trusted here, and pip
    # is given the same bundle: PIP_CERT)
    cp /etc/resolv.conf "$root/etc/resolv.conf"
    cp /etc/ssl/certs/ca-certificates.crt "$root/etc/ssl/certs/pi-check-host.crt"
    add_pi "$root"
    echo "  user pi: $(grep '^dialout:' "$root/etc/group")"
    # a fresh install every run (pip's cache is kept, as on a Pi that installed before)
    rm -rf "$root"/home/pi/.local/pipx "$root"/home/pi/.local/share/pipx "$root"/home/pi/.local/bin
    rm -f "$root"/home/pi/*.whl
    cp "$wheel" "$root/home/pi/"
    chown -R --reference="$root/home/pi" "$root/home/pi"
    unshare --mount --propagation private bash "$0" --in-root "$release" "$root" "$wheel" "$mode" \
        "$work/$release" || failed=1
done

echo "== figures (emulated figures are qemu's on this machine, not a Pi's)"
"$PYTHON" - "$work" $RELEASES <<'EOF'
import json, sys
from pathlib import Path
work, releases = Path(sys.argv[1]), sys.argv[2:]
def figures(label):
    found = {}
    path = work / f"{label}.figures"
    for line in path.read_text().splitlines() if path.exists() else []:
        for tag in ("INSTALL ", "FIGURES "):
            if line.startswith(tag):
                found.update(json.loads(line[len(tag):]))
    return found
host = figures("host")
rows = [("install (host: pip, a venv; roots: pipx)", "install_s", "s"),
        ("--check, mean per example", "check_s", "s"),
        ("--plan, mean per example", "plan_s", "s"),
        ("headless start to a hello answered", "start_s", "s"),
        ("... to the switch ok", "switch_ok_s", "s"),
        ("band change: datagram to relays set", "band_change_s", "s"),
        ("CPU per band change", "cpu_per_band_change_ms", "ms"),
        ("RSS after the band changes", "rss_mb", "MB"),
        ("SIGTERM to exit", "stop_s", "s"),
        ("window server start to a client answered", "window_s", "s")]
head = f"  {'':42}{'host':>10}" + "".join(f"{r:>10}{'ratio':>7}" for r in releases)
print(head)
for title, key, unit in rows:
    line = f"  {title:42}{str(host.get(key, '-')):>10}"
    for release in releases:
        value = figures(release).get(key, "-")
        ratio = (f"{value / host[key]:.1f}x" if isinstance(value, (int, float))
                 and host.get(key) else "")
        line += f"{str(value):>10}{ratio:>7}"
    print(f"{line}  {unit}")
EOF
if [ "$failed" != 0 ]; then
    echo "pi-check: FAILED (log: $LOG)"
    exit 1
fi
echo "pi-check: all passed (log: $LOG)"
}

if [ "${1:-}" = "--in-root" ]; then
    in_root "$@"
else
    main "$@"
fi
exit $?
