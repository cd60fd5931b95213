"""One place's half of ``scripts/pi-check.sh``: runs an installed moas-gui as a station
computer would and measures it.  Standard library only; it runs on this machine and
starts the programs either here or inside an arm64 root (``--root``, through ``chroot``
with qemu behind binfmt_misc, or ``proot -q qemu-aarch64-static``), so the same steps and
the same clocks serve both.

The steps, each a failure if it does not do what it should:

* ``moas-server --check`` and ``--plan`` on every example the wheel installed;
* ``socat`` links two pseudo-terminals (this machine's ``-x`` dump shows every byte on
  the cable); ``moas-emulator`` (this checkout's, playing the box, which is not on the
  tower computer) serves one end, the server opens the other;
* ``moas-server --headless`` on ``small-station.moas`` (its switch port set to that
  cable): time from start to a client's ``hello`` answered, the switch seen ``ok``;
* band changes of radio 1 from N1MM Logger ``RadioInfo`` datagrams, each answered by an
  antenna command (``!``) on the cable and a new relay set in the box; the server's CPU
  time over them (from ``/proc``);
* the running server's RSS and whether any Qt library is mapped into it (it must not be);
* the browser client's page; SIGTERM, and exit status 0;
* ``moas-server --install-service`` and ``systemd-analyze verify --user`` on its unit.

Prints what it does, then one line ``FIGURES {json}``; exits 1 at the first failure.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from pathlib import Path
from typing import Any

FREQUENCIES = (1402500, 702500, 2102500, 352500)  # N1MM's tens of hertz: 14025 kHz ...
BAND_CHANGES = 40
QT_LIBRARY = re.compile(r"libQt6|PySide6|shiboken6")


class Failure(Exception):
    """A step did not do what it should."""


class Place:
    """Where the programs run: this machine, or an arm64 root under emulation."""

    def __init__(self, args: argparse.Namespace) -> None:
        self.root: Path | None = Path(args.root) if args.root else None
        self.mode: str = args.mode
        self.bin: str = args.bin
        self.user: str = args.user
        self.work_inside = "/tmp/pi-check" if self.root else str(Path(args.work).resolve())
        self.work = self.outside(self.work_inside)
        self.owner = (0, 0)
        self.dialout = 0
        if self.root is not None:
            for line in (self.root / "etc" / "passwd").read_text().splitlines():
                fields = line.split(":")
                if fields[0] == self.user:
                    self.owner = (int(fields[2]), int(fields[3]))
            for line in (self.root / "etc" / "group").read_text().splitlines():
                fields = line.split(":")
                if fields[0] == "dialout":
                    self.dialout = int(fields[2])

    def make(self, folder: Path, mode: int = 0o700) -> None:
        """A folder the programs' user owns."""
        folder.mkdir(mode=mode, parents=True, exist_ok=True)
        os.chown(folder, *self.owner)

    def outside(self, inside: str) -> Path:
        """The path on this machine of ``inside`` (a path as the programs see it)."""
        return self.root / inside.lstrip("/") if self.root else Path(inside)

    def command(self, program: str, *arguments: str) -> list[str]:
        run = program if program.startswith("/") or program == "systemd-analyze" \
            else f"{self.bin}/{program}"
        if self.root is None:
            return [run, *arguments]
        home = f"/home/{self.user}"
        env = ["/usr/bin/env", "-i", f"HOME={home}", "LANG=C.UTF-8", "PYTHONUNBUFFERED=1",
               "QT_QPA_PLATFORM=offscreen",
               f"PATH={home}/.local/bin:/usr/local/bin:/usr/bin:/bin",
               *[f"{k}={v}" for k, v in self.xdg().items()]]
        if self.mode == "proot":
            return ["proot", "-q", "qemu-aarch64-static", "-r", str(self.root),
                    "-b", "/dev", "-b", "/proc", "-b", "/sys", "-w", home,
                    *env, run, *arguments]
        return ["chroot", f"--userspec={self.user}:{self.user}", str(self.root),
                *env, run, *arguments]

    def xdg(self) -> dict[str, str]:
        base = self.work_inside
        return {"XDG_RUNTIME_DIR": f"{base}/run", "XDG_STATE_HOME": f"{base}/state",
                "XDG_CONFIG_HOME": f"{base}/config", "XDG_DATA_HOME": f"{base}/data",
                "XDG_CACHE_HOME": f"{base}/cache"}

    def env(self) -> dict[str, str]:
        return dict(os.environ, PYTHONUNBUFFERED="1", QT_QPA_PLATFORM="offscreen", **self.xdg())


def say(text: str) -> None:
    print(f"  {text}", flush=True)


def run(place: Place, program: str, *arguments: str, timeout: float = 600) -> tuple[float, str]:
    started = time.monotonic()
    done = subprocess.run(place.command(program, *arguments), capture_output=True, text=True,
                          timeout=timeout, check=False, env=place.env())
    took = time.monotonic() - started
    if done.returncode != 0:
        raise Failure(f"{program} {' '.join(arguments)}: status {done.returncode}\n"
                      f"{done.stdout[-2000:]}{done.stderr[-2000:]}")
    return took, done.stdout


def terminate(place: Place, server: subprocess.Popen[bytes]) -> None:
    """SIGTERM to the server: under proot to its tracee (proot does not pass it on)."""
    targets = process_tree(server.pid)[1:] if place.mode == "proot" else []
    for pid in targets or [server.pid]:
        os.kill(pid, signal.SIGTERM)


def free_port(kind: int = socket.SOCK_STREAM) -> int:
    with socket.socket(socket.AF_INET, kind) as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def process_tree(pid: int) -> list[int]:
    """``pid`` and its descendants (under proot the server is proot's child)."""
    parents: dict[int, int] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            parents[int(entry.name)] = int(fields[1])
    tree, grew = [pid], True
    while grew:
        more = [child for child, parent in parents.items() if parent in tree and child not in tree]
        tree.extend(more)
        grew = bool(more)
    return tree


def cpu_seconds(pid: int) -> float:
    total = 0
    for member in process_tree(pid):
        fields = Path(f"/proc/{member}/stat").read_text().rsplit(")", 1)[1].split()
        total += int(fields[11]) + int(fields[12])
    return total / os.sysconf("SC_CLK_TCK")


def memory_kb(pid: int, name: str) -> int:
    """The largest ``name`` (VmRSS, VmHWM) among ``pid`` and its descendants."""
    found = []
    for member in process_tree(pid):
        for line in Path(f"/proc/{member}/status").read_text().splitlines():
            if line.startswith(name + ":"):
                found.append(int(line.split()[1]))
    if not found:
        raise Failure(f"no {name} in /proc/{pid}/status")
    return max(found)


def qt_mapped(pid: int) -> list[str]:
    mapped: set[str] = set()
    for member in process_tree(pid):
        maps = Path(f"/proc/{member}/maps").read_text().splitlines()
        mapped |= {line.split()[-1] for line in maps if QT_LIBRARY.search(line)}
    return sorted(mapped)


class Cable:
    """``socat -x`` between two pseudo-terminals; collects what the server sends the box."""

    def __init__(self, work: Path) -> None:
        self.server_end, self.box_end = work / "switch", work / "box"
        self.sent = bytearray()
        self.lock = threading.Lock()
        self.process = subprocess.Popen(
            ["socat", "-x", "-d", "-d", f"pty,raw,echo=0,link={self.server_end}",
             f"pty,raw,echo=0,link={self.box_end}"],
            stderr=subprocess.PIPE, text=True)
        threading.Thread(target=self._read, daemon=True).start()
        end = time.monotonic() + 20
        while not (self.server_end.exists() and self.box_end.exists()):
            if time.monotonic() > end or self.process.poll() is not None:
                raise Failure("socat made no pseudo-terminal pair")
            time.sleep(0.05)

    def _read(self) -> None:
        assert self.process.stderr is not None
        to_box = False
        for line in self.process.stderr:
            if line.startswith(("> ", "< ")):
                to_box = line.startswith(">")
            elif line.startswith(" ") and to_box:
                with self.lock:
                    self.sent.extend(bytes.fromhex(line.strip()))

    def mark(self) -> int:
        with self.lock:
            return len(self.sent)

    def since(self, mark: int) -> bytes:
        with self.lock:
            return bytes(self.sent[mark:])

    def close(self) -> None:
        self.process.terminate()
        self.process.wait(10)


class Box:
    """``moas-emulator --headless`` on the cable's far end; follows its relay log lines."""

    def __init__(self, emulator: str, port: Path) -> None:
        self.lines: list[str] = []
        self.process = subprocess.Popen([emulator, "--headless", "--port", str(port),
                                         "--log-level", "info"],
                                        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                        text=True)
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.process.stderr is not None
        for line in self.process.stderr:
            self.lines.append(line.rstrip())

    def relay_lines(self) -> list[str]:
        return [line for line in list(self.lines) if " relays " in f" {line}"]

    def close(self) -> None:
        self.process.terminate()
        self.process.wait(10)


class Client:
    """A client of the server's TCP protocol (one request at a time, events skipped)."""

    def __init__(self, port: int, timeout: float) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=timeout)
        self.reader = self.sock.makefile("rb")
        self.next_id = 0

    def ask(self, cmd: str, **fields: object) -> dict[str, Any]:
        self.next_id += 1
        request = {"id": self.next_id, "cmd": cmd, **fields}
        self.sock.sendall(json.dumps(request).encode() + b"\n")
        while True:
            line = self.reader.readline()
            if not line:
                raise Failure(f"the server closed the connection while {cmd!r} was asked")
            message = json.loads(line)
            if message.get("id") == self.next_id:
                if "error" in message:
                    raise Failure(f"{cmd}: {message['error']}")
                return message  # type: ignore[no-any-return]

    def close(self) -> None:
        self.sock.close()


def radio_info(radio: int, frequency: int) -> bytes:
    return ('<?xml version="1.0" encoding="utf-8"?><RadioInfo><app>N1MM</app>'
            "<StationName>PI-CHECK</StationName>"
            f"<RadioNr>{radio}</RadioNr><Freq>{frequency}</Freq><TXFreq>{frequency}</TXFreq>"
            "<Mode>CW</Mode><OpCall>N0CALL</OpCall><IsRunning>False</IsRunning>"
            f"<FocusRadioNr>{radio}</FocusRadioNr><ActiveRadioNr>{radio}</ActiveRadioNr>"
            "<IsStereo>False</IsStereo><IsSplit>False</IsSplit>"
            "<IsTransmitting>False</IsTransmitting></RadioInfo>").encode()


def wait(condition: Any, timeout: float, what: str, server: subprocess.Popen[bytes]) -> Any:
    end = time.monotonic() + timeout
    while True:
        if server.poll() is not None:
            raise Failure(f"the server ended (status {server.returncode}) while {what}")
        try:
            got = condition()
        except OSError:
            got = None
        if got:
            return got
        if time.monotonic() > end:
            raise Failure(f"timed out ({timeout:.0f} s) while {what}")
        time.sleep(0.02)


def check_examples(place: Place, examples: str, figures: dict[str, Any]) -> None:
    names = sorted(p.name for p in place.outside(examples).glob("*.moas"))
    if not names:
        raise Failure(f"no examples in {examples}")
    check = plan = 0.0
    for name in names:
        took, out = run(place, "moas-server", "--check", f"{examples}/{name}")
        check += took
        took2, out2 = run(place, "moas-server", "--plan", f"{examples}/{name}")
        plan += took2
        if not out.strip() or not out2.strip():
            raise Failure(f"--check or --plan printed nothing for {name}")
        say(f"ok  --check {took:5.2f} s, --plan {took2:5.2f} s  {name}")
    figures["examples"] = len(names)
    figures["check_s"] = round(check / len(names), 3)
    figures["plan_s"] = round(plan / len(names), 3)


def station_file(place: Place, examples: str) -> str:
    data = json.loads((place.outside(examples) / "small-station.moas").read_text())
    data["Switches"][0]["Port"] = f"{place.work_inside}/switch"
    data["N1MMLogger"] = [{"Address": "127.0.0.1", "Station": 1}]
    data["UseN1MMLogger"] = True
    (place.work / "station.moas").write_text(json.dumps(data, indent=2))
    return f"{place.work_inside}/station.moas"


def band_changes(server: subprocess.Popen[bytes], cable: Cable, box: Box, udp: int,
                 timeout: float, figures: dict[str, Any]) -> None:
    logger = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    logger.bind(("127.0.0.1", 0))
    cpu_before = cpu_seconds(server.pid)
    started = time.monotonic()
    first: bytes = b""
    for count in range(BAND_CHANGES):
        frequency = FREQUENCIES[count % len(FREQUENCIES)]
        mark, relays = cable.mark(), len(box.relay_lines())
        logger.sendto(radio_info(1, frequency), ("127.0.0.1", udp))
        sent = wait(lambda m=mark: b"!" in cable.since(m) and cable.since(m), timeout,
                    f"radio 1 went to {frequency / 100:.1f} kHz: no antenna command on the"
                    " cable", server)
        wait(lambda r=relays: len(box.relay_lines()) > r, timeout,
             f"radio 1 went to {frequency / 100:.1f} kHz: the box's relays did not change",
             server)
        if count == 0:
            first = sent
            say(f"ok  logger datagram (radio 1, {frequency / 100:.1f} kHz) answered on the "
                f"cable with {sent!r}; the box: {box.relay_lines()[-1].split(' relays ')[-1]}")
    took = time.monotonic() - started
    cpu = cpu_seconds(server.pid) - cpu_before
    logger.close()
    figures["band_changes"] = BAND_CHANGES
    figures["band_change_s"] = round(took / BAND_CHANGES, 4)
    figures["cpu_per_band_change_ms"] = round(1000 * cpu / BAND_CHANGES, 2)
    figures["first_relay_bytes"] = first.decode("ascii", "replace")
    say(f"ok  {BAND_CHANGES} band changes, each answered with relay bytes: "
        f"{1000 * took / BAND_CHANGES:.0f} ms each, {1000 * cpu / BAND_CHANGES:.1f} ms CPU each")


def headless(place: Place, args: argparse.Namespace, config: str,
             figures: dict[str, Any]) -> None:
    for sub in ("run", "state", "config", "data", "cache"):
        place.make(place.work / sub)
    cable = Cable(place.work)
    if place.root is not None:  # as udev gives a USB serial adapter: root:dialout, 0660
        device = os.path.realpath(cable.server_end)
        os.chown(device, 0, place.dialout)
        os.chmod(device, 0o660)
        say(f"ok  the cable's end for the server, {device}, made root:dialout 0660 (as a USB"
            f" serial adapter is); {place.user} reaches it through the dialout group")
    box = Box(args.emulator, cable.box_end)
    tcp, udp, web = free_port(), free_port(socket.SOCK_DGRAM), free_port()
    log = (place.work / "server.log").open("wb")
    started = time.monotonic()
    server = subprocess.Popen(place.command(
        "moas-server", config, "--headless", "--new-instance", "--bind", "127.0.0.1",
        "--tcp-port", str(tcp), "--udp-port", str(udp), "--udp-bind", "127.0.0.1",
        "--web-port", str(web), "--no-rotator-program", "--log-level", "info"),
        stderr=log, env=place.env())
    try:
        client = wait(lambda: Client(tcp, args.timeout), args.timeout,
                      "waiting for the client port", server)
        hello = client.ask("hello", client="pi-check")
        figures["start_s"] = round(time.monotonic() - started, 2)
        say(f"ok  headless server up, a client's hello answered after {figures['start_s']} s:"
            f" {json.dumps(hello.get('result'))[:100]}")

        def switch_ok() -> bool:
            switches = client.ask("state")["result"].get("switches", [])
            return any(s.get("status") == "ok" for s in switches)
        wait(switch_ok, args.timeout, "waiting for the switch on the cable to be ok", server)
        figures["switch_ok_s"] = round(time.monotonic() - started, 2)
        say(f"ok  switch 1 ok on the pseudo-terminal after {figures['switch_ok_s']} s")
        band_changes(server, cable, box, udp, args.timeout, figures)
        figures["rss_mb"] = round(memory_kb(server.pid, "VmRSS") / 1024, 1)
        figures["peak_rss_mb"] = round(memory_kb(server.pid, "VmHWM") / 1024, 1)
        qt = qt_mapped(server.pid)
        if qt:
            raise Failure(f"the headless server has Qt loaded: {qt[:3]}")
        say(f"ok  RSS {figures['rss_mb']} MB (peak {figures['peak_rss_mb']} MB); "
            "no Qt library mapped into the headless server")
        with urllib.request.urlopen(f"http://127.0.0.1:{web}/", timeout=args.timeout) as page:
            if b"<html" not in page.read().lower():
                raise Failure("the browser client's page is not HTML")
        say("ok  the browser client's page served")
        client.close()
        stopping = time.monotonic()
        terminate(place, server)
        status = server.wait(args.timeout)
        figures["stop_s"] = round(time.monotonic() - stopping, 2)
        if status != 0:
            raise Failure(f"the server ended with status {status} on SIGTERM")
        say(f"ok  SIGTERM: stopped with status 0 after {figures['stop_s']} s")
    except Failure:
        log.flush()
        print((place.work / "server.log").read_text(errors="replace")[-3000:], file=sys.stderr)
        raise
    finally:
        if server.poll() is None:
            server.kill()
        log.close()
        box.close()
        cable.close()


def window(place: Place, examples: str, timeout: float, figures: dict[str, Any]) -> None:
    """The window server (offscreen) on small-station.moas as shipped (its switch the
    built-in emulator): up, a client answered, Qt mapped (the Qt check can fire), SIGTERM."""
    tcp = free_port()
    log = (place.work / "window.log").open("wb")
    started = time.monotonic()
    server = subprocess.Popen(place.command(
        "moas-server-gui", f"{examples}/small-station.moas", "--new-instance",
        "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0", "--web-port", "0",
        "--no-rotator-program"), stderr=log, env=place.env())
    try:
        client = wait(lambda: Client(tcp, timeout), timeout, "waiting for the window server",
                      server)
        client.ask("hello", client="pi-check")
        figures["window_s"] = round(time.monotonic() - started, 2)
        client.close()
        qt = qt_mapped(server.pid)
        if not qt:
            raise Failure("the window server shows no Qt library in /proc/PID/maps: the "
                          "headless server's Qt check could not see one either")
        terminate(place, server)
        status = server.wait(timeout)
        if status != 0:
            raise Failure(f"the window server ended with status {status} on SIGTERM")
        say(f"ok  the window server (offscreen) answered a client after {figures['window_s']} s"
            f" with {len(qt)} Qt libraries mapped, and stopped with status 0")
    except Failure:
        log.flush()
        print((place.work / "window.log").read_text(errors="replace")[-3000:], file=sys.stderr)
        raise
    finally:
        if server.poll() is None:
            server.kill()
        log.close()


def service(place: Place, config: str, figures: dict[str, Any]) -> None:
    unit = f"{place.work_inside}/config/systemd/user/moas-server.service"
    run(place, "moas-server", config, "--install-service", "--web-port", "8080")
    text = place.outside(unit).read_text()
    execs = [line for line in text.splitlines() if line.startswith("ExecStart=")]
    took, _ = run(place, "systemd-analyze", "verify", "--user", unit)
    say(f"ok  --install-service: systemd-analyze verify --user accepts the unit "
        f"({execs[0][:110] if execs else 'no ExecStart'})")
    figures["verify_s"] = round(took, 2)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--label", required=True)
    parser.add_argument("--root", default="", help="an arm64 root (empty: this machine)")
    parser.add_argument("--mode", choices=("chroot", "proot"), default="chroot")
    parser.add_argument("--user", default="pi")
    parser.add_argument("--bin", required=True, help="the installed programs, as seen there")
    parser.add_argument("--examples", required=True, help="the installed examples, as seen")
    parser.add_argument("--emulator", required=True, help="moas-emulator on this machine")
    parser.add_argument("--work", default="", help="a fresh folder for this machine's run"
                        " (in a root: its /tmp/pi-check)")
    parser.add_argument("--timeout", type=float, default=60)
    parser.add_argument("--window", action="store_true",
                        help="also start the window server (offscreen) and answer a client")
    args = parser.parse_args()
    place = Place(args)
    if place.work.exists():
        shutil.rmtree(place.work)
    place.make(place.work, 0o755)
    figures: dict[str, Any] = {"label": args.label}
    try:
        check_examples(place, args.examples, figures)
        config = station_file(place, args.examples)
        headless(place, args, config, figures)
        service(place, config, figures)
        if args.window:
            window(place, args.examples, args.timeout, figures)
    except (Failure, OSError, subprocess.SubprocessError) as problem:
        print(f"FAIL [{args.label}]: {problem}", flush=True)
        print("FIGURES " + json.dumps(figures), flush=True)
        return 1
    print("FIGURES " + json.dumps(figures), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
