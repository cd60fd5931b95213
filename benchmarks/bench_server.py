"""The server's speed targets, measured on the real program as a station runs it.

Run:  .venv/bin/python benchmarks/bench_server.py [--runs 3] [--rate 1000[,500,...]]
          [--seconds 10] [--flood small,big,tune] [--no-window] [--idle SECONDS]

Prints one table:

(a) **Start-up and memory.**  ``moas-server examples/big-station.moas`` as a
    separate process, with the window (``QT_QPA_PLATFORM=offscreen``) and
    headless: the time from just before the process is spawned to the log
    record "Opened big-station.moas in N ms" (the configuration runs; the
    window's title and status bar name the file in the same instant), and for
    the window also until its status bar shows both switches answering.
    Resident memory (VmRSS, ``/proc/PID/status``) one second after "Opened",
    and the peak (VmHWM); then SIGTERM until the process has ended (the
    journeys in tests/ check that Exit and SIGTERM end it, not how soon).
    Targets: start < 2 s, RSS < 150 MB, stop < 2 s.
(b) **N1MM Logger flood.**  A sender process plays N1MM Logger+ at 1,000
    RadioInfo packets a second for 10 s over real UDP on 127.0.0.1 into
    ``moas-server --headless``.  The switches are emulated boxes on
    pseudo-terminals served by *this* process, which timestamps every read
    from a terminal.  Latency: from ``sendto`` in the sender to the arrival
    of the first byte of the antenna command (``!<port>...;``) the packet
    caused (both processes read CLOCK_MONOTONIC).  Target: p99 < 5 ms, each
    second's count and p99 flat (no backlog).  Floods:

    ``small``  the SO2R small station; radios 1 and 2 of one N1MM computer take
               turns, and every packet moves its radio to another band: every
               packet is an antenna change on the one switch;
    ``big``    the big station's station 1 (its N1MM computer is 127.0.0.1) on
               its two switches, every packet another band;
    ``tune``   the small station with both VFOs turning: every packet another
               frequency, one in fifty another band (a contest's traffic, sped
               up); latency is measured on the band changes.

    Which command answers which packet: the bench replays the same packets
    through the same engine and switch planner in this process, so it knows
    the command each packet must cause, and walks each switch port's
    commands in order beside the packets.
(c) **Bytes on the wire** for band changes on the big station (the switch
    link's planner), and per band change as counted on the terminals in (b).
(d) **Where the time goes**: the parts of a band change timed alone here (CPU
    time: parse RadioInfo, the engine's decision, the switch plan and its bytes).
    ``--costs`` adds the server's CPU per quiet band change by thread, by event-loop
    callback and by part of the path; ``--profile`` a cProfile of the loop's thread;
    ``--trace`` the stages of a quiet packet's latency (``quiet_path.py``); ``--idle
    SECONDS`` the server's own CPU with no packet (its periodic work, which a quiet
    flood's figure shares among its band changes), by loop callback with ``--costs``.
    The server's CPU is read to the nanosecond (its process's CPU-time clock), not in
    ``/proc``'s 10 ms ticks.
(e) **The quiet path's targets** (issue 33), from figures of the same run: server
    CPU per band change at 10/s at most 5 times the parts of (d) together, and
    packet to first byte at 10/s (median) at most 0.6 ms above the floor's
    (``--floor``, the same hops with no work between them).

How the server is started: ``python bench_server.py --serve ARGS`` runs
``moas_gui.cli.server.main(ARGS)`` with two additions that change nothing
measured: the N1MM socket is bound to the ``--bind`` address (127.0.0.1)
rather than every address (the command line has no option for that), and a
logging handler prints a marker with the monotonic clock when "Opened ..." is
logged, then removes itself.  Every run uses ``--new-instance`` (never hands
the file to a server already running), free ports and a throw-away settings
folder; the MOAS Rotator program is not started.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import logging
import os
import platform
import re
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
import quiet_path  # beside this file

BIG = ROOT / "examples" / "big-station.moas"
SMALL = ROOT / "examples" / "small-station.moas"
MARK = "BENCH-MARK"

QUIET_RATE = 10
"""Packets a second at or below which a flood is held to the quiet-rate target."""

Ref = tuple[int, int]
"""(station, radio)."""
Row = tuple[str, str, str, str]
"""One line of the table: measure, figure, target, verdict."""


def _tuning(bands: Sequence[float], steps: int = 50) -> tuple[float, ...]:
    """A VFO turning in 100 Hz steps, ``steps`` on each band in turn."""
    return tuple(round(base + 0.1 * i, 1) for base in bands for i in range(steps))


@dataclass(frozen=True, slots=True)
class Flood:
    title: str
    config: Path
    cycles: dict[Ref, tuple[float, ...]]
    """The frequencies (kHz) each radio runs through, one per packet of that radio."""


# Three bands per radio whose antenna commands differ; never one band on two radios at once.
FLOODS = {
    "small": Flood("small-station SO2R, every packet a band change", SMALL,
                   {(1, 1): (14025.0, 7025.0, 28025.0), (1, 2): (21025.0, 3525.0, 7125.0)}),
    "big": Flood("big-station, two switches, every packet a band change", BIG,
                 {(1, 1): (14025.0, 7025.0, 21025.0)}),
    "tune": Flood("small-station SO2R, VFOs turning, band change 1 in 50", SMALL,
                  {(1, 1): _tuning((14025.0, 7025.0, 28025.0)),
                   (1, 2): _tuning((21025.0, 3525.0, 7125.0))}),
}


def flood_packets(flood: Flood, count: int) -> list[tuple[Ref, float]]:
    """(radio, kHz) of each packet: the radios take turns, each on its next frequency."""
    radios = sorted(flood.cycles)
    packets = []
    for seq in range(count):
        ref = radios[seq % len(radios)]
        cycle = flood.cycles[ref]
        packets.append((ref, cycle[(seq // len(radios)) % len(cycle)]))
    return packets


# --------------------------------------------------------------------------- the server


class _MarkHandler(logging.Handler):
    """Prints a marker with the monotonic clock when the server logs "Opened ..."."""

    def __init__(self, window: bool) -> None:
        super().__init__(logging.INFO)
        self.window = window

    def emit(self, record: logging.LogRecord) -> None:
        message = record.getMessage()
        if not message.startswith("Opened "):
            return
        print(f"{MARK} opened {time.monotonic_ns()} {message}", flush=True)
        logging.getLogger("moas_gui.app").removeHandler(self)  # nothing to add to a flood
        if self.window:
            from PySide6.QtCore import QTimer

            QTimer.singleShot(0, self._watch_window)

    def _watch_window(self) -> None:
        """Mark when the window names the file, then when every switch answers."""
        from PySide6.QtCore import QTimer
        from PySide6.QtWidgets import QApplication, QMainWindow

        shown = [w for w in QApplication.topLevelWidgets() if isinstance(w, QMainWindow)
                 and w.windowTitle().endswith(" - MOAS Server")]
        if not shown:
            QTimer.singleShot(5, self._watch_window)
            return
        print(f"{MARK} shown {time.monotonic_ns()} {shown[0].windowTitle()}", flush=True)
        self._watch_switches(shown[0], time.monotonic() + 10)

    def _watch_switches(self, window: Any, give_up: float) -> None:
        from PySide6.QtCore import QTimer

        text = window.statusBar().currentMessage()
        if "switch" in text and "connecting" not in text and "unresponsive" not in text:
            print(f"{MARK} ready {time.monotonic_ns()} {text}", flush=True)
        elif time.monotonic() < give_up:
            QTimer.singleShot(5, lambda: self._watch_switches(window, give_up))


def serve_child(argv: list[str]) -> int:
    """``moas-server ARGS``, N1MM socket on the ``--bind`` address, with the "Opened" marker."""
    import dataclasses

    from moas_gui.cli import server as cli

    original = cli._options

    def loopback_options(args: argparse.Namespace) -> object:
        return dataclasses.replace(original(args), udp_bind=args.bind)  # type: ignore[type-var]

    cli._options = loopback_options  # type: ignore[assignment]
    logging.getLogger("moas_gui.app").addHandler(_MarkHandler(window="--headless" not in argv))
    if os.environ.get(quiet_path.TRACE_ENV):
        quiet_path.install_stamps(os.environ[quiet_path.TRACE_ENV])
    if os.environ.get(quiet_path.COSTS_ENV):
        quiet_path.install_costs(os.environ[quiet_path.COSTS_ENV])
    elif os.environ.get(quiet_path.PROFILE_ENV):
        quiet_path.install_profiler(os.environ[quiet_path.PROFILE_ENV])
    return cli.main(argv)


# --------------------------------------------------------------------------- the sender


def send(port: int, plan_json: str) -> None:
    """The N1MM Logger computer: paced RadioInfo packets, then their send times as JSON."""
    from moas_gui.sources.n1mm_packet import radio_info_packet

    plan = json.loads(plan_json)
    rate = plan["rate"]
    packets = [radio_info_packet(ref[1], khz, station_name="BENCH-PC")
               for ref, khz in flood_packets(FLOODS[plan["flood"]], plan["count"])]
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sent = [0] * len(packets)
    start = time.monotonic() + 0.1
    for seq, data in enumerate(packets):
        delay = start + seq / rate - time.monotonic()
        if delay > 0:
            time.sleep(delay)  # no busy wait: the two cores belong to the server and the switches
        sent[seq] = time.monotonic_ns()
        sock.sendto(data, ("127.0.0.1", port))
    sock.close()
    print(json.dumps(sent))


# --------------------------------------------------------------------------- /proc and friends


def proc_status(pid: int) -> dict[str, int]:
    """VmRSS and VmHWM of ``pid`` in kB (empty when it is gone)."""
    found: dict[str, int] = {}
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            name, _, value = line.partition(":")
            if name in ("VmRSS", "VmHWM"):
                found[name] = int(value.split()[0])
    except OSError:
        pass
    return found


def minor_faults(pid: int) -> int:
    """Minor page faults of ``pid`` so far (memory the system had to hand it afresh)."""
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[7])
    except (OSError, IndexError, ValueError):
        return 0


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of ``pid`` so far (to the nanosecond where the system's
    CPU-time clock of another process works, :func:`quiet_path.cpu_clock`)."""
    precise = quiet_path.cpu_clock(pid)
    if precise is not None:
        return precise
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def own_cpu() -> float:
    """CPU seconds of this process (the emulated switches, during a flood)."""
    usage = os.times()
    return usage.user + usage.system


def machine_busy() -> float:
    """CPU seconds all cores spent busy so far (/proc/stat)."""
    try:
        fields = [int(x) for x in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]]
    except (OSError, ValueError):
        return 0.0
    return (sum(fields[:8]) - fields[3] - fields[4]) / os.sysconf("SC_CLK_TCK")


def udp_queue(port: int) -> tuple[int, int]:
    """(receive-queue bytes, drops) of the UDP socket bound to ``port`` (/proc/net/udp)."""
    try:
        lines = Path("/proc/net/udp").read_text().splitlines()[1:]
    except OSError:
        return 0, 0
    for line in lines:
        parts = line.split()
        if int(parts[1].split(":")[1], 16) == port:
            return int(parts[4].split(":")[1], 16), int(parts[-1])
    return 0, 0


def pct(values: Sequence[float], p: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(p / 100 * len(ordered)))] if ordered else float("nan")


def machine() -> str:
    model = next((line.split(":", 1)[1].strip() for line in _cpuinfo()
                  if line.startswith("model name")), platform.machine())
    return (f"{os.cpu_count()} cores ({model}), load average {_load()}, "
            f"Python {platform.python_version()}, {platform.system()} {platform.release()}")


def _cpuinfo() -> list[str]:
    try:
        return Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:
        return []


def _load() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def _verdict(ok: bool) -> str:
    return "PASS" if ok else "FAIL"


# --------------------------------------------------------------------------- running a server


def child_env(settings: Path, window: bool) -> dict[str, str]:
    env = dict(os.environ, PYTHONUNBUFFERED="1", XDG_CONFIG_HOME=str(settings),
               XDG_STATE_HOME=str(settings / "state"), XDG_DATA_HOME=str(settings / "data"))
    if window:
        env["QT_QPA_PLATFORM"] = "offscreen"
    return env


def server_args(config: Path, headless: bool) -> list[str]:
    return [*(["--headless"] if headless else []), str(config), "--bind", "127.0.0.1",
            "--tcp-port", "0", "--udp-port", "0", "--no-rotator-program", "--new-instance"]


async def spawn_server(args: list[str], env: dict[str, str],
                       stderr: Path) -> tuple[asyncio.subprocess.Process, int]:
    """The server process, and the monotonic clock just before it was spawned."""
    started = time.monotonic_ns()
    with stderr.open("wb") as err:
        process = await asyncio.create_subprocess_exec(
            sys.executable, __file__, "--serve", *args,
            stdout=asyncio.subprocess.PIPE, stderr=err, env=env, cwd=str(ROOT))
    return process, started


async def read_marks(process: asyncio.subprocess.Process, wanted: set[str],
                     timeout: float) -> dict[str, tuple[int, str]]:
    """Marker name -> (monotonic ns, text), until every name in ``wanted`` came or time ran out."""
    assert process.stdout is not None
    marks: dict[str, tuple[int, str]] = {}
    loop = asyncio.get_running_loop()
    end = loop.time() + timeout
    while not wanted <= marks.keys():
        try:
            line = await asyncio.wait_for(process.stdout.readline(), max(0.01, end - loop.time()))
        except TimeoutError:
            break
        if not line:
            break
        parts = line.decode(errors="replace").rstrip().split(maxsplit=3)
        if len(parts) >= 3 and parts[0] == MARK:
            marks[parts[1]] = (int(parts[2]), parts[3] if len(parts) > 3 else "")
    return marks


async def stop(process: asyncio.subprocess.Process) -> float:
    """SIGTERM, then the seconds until the process ended (nan when it had to be killed)."""
    if process.returncode is not None:
        return float("nan")
    began = time.monotonic()
    process.send_signal(signal.SIGTERM)
    try:
        await asyncio.wait_for(process.wait(), 10)
    except TimeoutError:
        process.kill()
        await process.wait()
        return float("nan")
    return time.monotonic() - began


# --------------------------------------------------------------------------- (a) start-up


@dataclass
class StartRun:
    seconds: dict[str, float]
    """Marker name -> seconds since the spawn."""
    open_ms: float
    """What the server itself logged for loading and starting the file."""
    rss_kb: int
    hwm_kb: int
    stop_s: float = float("nan")
    """SIGTERM to the process's end (the journeys check that it ends, this how soon)."""


async def start_once(headless: bool, work: Path) -> StartRun:
    stderr = work / f"start-{'headless' if headless else 'window'}.log"
    process, started = await spawn_server(server_args(BIG, headless),
                                          child_env(work / "settings", not headless), stderr)
    try:
        wanted = {"opened"} if headless else {"opened", "shown", "ready"}
        marks = await read_marks(process, wanted, timeout=30)
        if "opened" not in marks:
            raise RuntimeError("the server never logged Opened:\n" + stderr.read_text()[-3000:])
        await asyncio.sleep(1.0)
        memory = proc_status(process.pid)
    finally:
        stop_s = await stop(process)
    found = re.search(r" in (\d+) ms", marks["opened"][1])
    return StartRun(seconds={name: (at - started) / 1e9 for name, (at, _) in marks.items()},
                    open_ms=float(found.group(1)) if found else float("nan"),
                    rss_kb=memory.get("VmRSS", 0), hwm_kb=memory.get("VmHWM", 0),
                    stop_s=stop_s)


async def bench_start(runs: int, window: bool, work: Path) -> list[Row]:
    rows: list[Row] = []
    for headless in ([False] if window else []) + [True]:
        label = "headless" if headless else "window, offscreen"
        results = [await start_once(headless, work) for _ in range(runs)]

        def spread(name: str, results: list[StartRun] = results) -> list[float]:
            return [r.seconds[name] for r in results if name in r.seconds]

        opened = spread("opened")
        rows.append((f"start to 'Opened big-station.moas' ({label})",
                     (f"median {statistics.median(opened):.2f} s, max {max(opened):.2f} s "
                     f"({runs} runs)"), "< 2 s", _verdict(max(opened) < 2.0)))
        if spread("ready"):
            rows.append(("  to the status bar showing both switches ok",
                         (f"median {statistics.median(spread('ready')):.2f} s, "
                         f"max {max(spread('ready')):.2f} s"), "", ""))
        rows.append(("  of which the server loading and starting the file",
                     f"median {statistics.median(r.open_ms for r in results):.0f} ms", "", ""))
        rss = [r.rss_kb / 1024 for r in results]
        rows.append((f"resident memory 1 s after 'Opened' ({label})",
                     (f"{statistics.median(rss):.0f} MB "
                     f"(peak {max(r.hwm_kb for r in results) / 1024:.0f} MB)"),
                     "< 150 MB", _verdict(max(rss) < 150)))
        stops = [r.stop_s for r in results]
        rows.append((f"SIGTERM to the end of the process ({label})",
                     f"median {statistics.median(stops):.2f} s, max {max(stops):.2f} s",
                     "< 2 s", _verdict(max(stops) < 2.0)))
    return rows


# --------------------------------------------------------------------------- (b) the flood


@dataclass
class Terminal:
    """One emulated switch on a pseudo-terminal, with the time of every read from it."""

    switch_id: int
    box: Any
    endpoint: Any
    reads: list[tuple[int, bytes]] = field(default_factory=list)

    def commands(self) -> list[tuple[int, str]]:
        """Every ``;``-ended command, with the arrival time of the read holding its first byte."""
        found: list[tuple[int, str]] = []
        partial, partial_at = "", 0
        for at, data in self.reads:
            for ch in data.decode("latin-1"):
                if not partial:
                    partial_at = at
                partial += ch
                if ch == ";":
                    found.append((partial_at, partial))
                    partial = ""
        return found


def flood_config(name: str, work: Path, links: dict[int, Path]) -> Path:
    """The example with its switches on the terminals and 127.0.0.1 as station 1's logger."""
    data = json.loads(FLOODS[name].config.read_text())
    for switch in data["Switches"]:
        switch["Port"] = str(links[switch["ID"]])
    data["UseN1MMLogger"] = True
    data["N1MMLogger"] = [{"Address": "127.0.0.1", "Station": 1}]
    data["StartMOASRotator"] = False
    path = work / f"flood-{name}.moas"
    path.write_text(json.dumps(data, indent=1))
    return path


def switch_ports(config: Any, ref: Ref) -> dict[int, int]:
    """Switch id -> the port of that switch that radio ``ref`` is wired to."""
    only = config.switches[0].id if len(config.switches) == 1 else 0
    return {sp.switch or only: sp.port for sp in config.radio(*ref).switches}


def expected_commands(flood: Flood, packets: list[tuple[Ref, float]]) -> list[dict[int, str]]:
    """For each packet, switch id -> the antenna command it must cause there (none: nothing).

    The same engine and switch planner the server runs, fed the same
    frequencies in the same order (the warm-up first).
    """
    from moas_gui.config import load_config
    from moas_gui.engine import Engine
    from moas_gui.hw.moas2.sync import difference

    config = load_config(flood.config).unwrap()
    engine = Engine(config)
    states = engine.switch_states()
    ports = {ref: switch_ports(config, ref) for ref in flood.cycles}

    def feed(ref: Ref, khz: float, now: float) -> dict[int, str]:
        caused: dict[int, str] = {}
        for switch_id, state in engine.set_frequency(*ref, khz, now=now).switches.items():
            text = difference(states[switch_id], state).encode().decode("latin-1")
            states[switch_id] = state
            port = ports[ref].get(switch_id)
            mine = [c + ";" for c in text.split(";")
                    if port is not None and c.startswith(f"!{port}")]
            if mine:
                caused[switch_id] = mine[0]
        return caused

    for ref in sorted(flood.cycles):
        feed(ref, flood.cycles[ref][-1], 0.0)
    return [feed(ref, khz, 1.0 + seq / 1000) for seq, (ref, khz) in enumerate(packets)]


def match(sent: list[int], packets: list[tuple[Ref, float]], expected: list[dict[int, str]],
          terminals: dict[int, Terminal], config: Any) -> dict[int, float]:
    """Packet number -> ms from its ``sendto`` until the switch holds what it, or a newer
    packet of the same radio, asks for (the first byte of that command).

    For each radio and switch port, walk the commands that port received in order
    beside the radio's packets: a command answers the newest packet sent before it
    whose expected command it is, and every older packet still waiting too -- the
    server skipped those because a newer frequency had already arrived, so they
    waited exactly that long for the switch to be up to date.  A packet that no
    command ever answers stays unanswered.  Where one packet causes commands on
    several switches, the earliest counts.
    """
    latencies: dict[int, float] = {}
    commands = {switch_id: t.commands() for switch_id, t in terminals.items()}
    for ref in sorted({ref for ref, _ in packets}):
        for switch_id, port in switch_ports(config, ref).items():
            waiting = [seq for seq, (packet_ref, _) in enumerate(packets)
                       if packet_ref == ref and expected[seq].get(switch_id) is not None]
            cursor = 0
            for at, text in commands.get(switch_id, []):
                if not text.startswith(f"!{port}"):
                    continue
                # The server acts on the newest frequency it has read, so a command
                # answers the newest waiting packet sent before it that asks for it.
                found = None
                for k in range(cursor, len(waiting)):
                    if sent[waiting[k]] > at:
                        break
                    if expected[waiting[k]][switch_id] == text:
                        found = k
                if found is None:
                    continue
                for seq in waiting[cursor:found + 1]:
                    delay = (at - sent[seq]) / 1e6
                    latencies[seq] = min(delay, latencies.get(seq, delay))
                cursor = found + 1
    return latencies


@dataclass
class FloodResult:
    name: str
    rate: int
    sent: int
    expected: int
    """Packets that must cause an antenna command."""
    latencies: dict[int, float]
    per_second: list[tuple[int, int, float]]
    """For each second: (packets answered, packets that had to change antennas, p99 ms)."""
    bytes_per_change: dict[int, float]
    udp_queue_max: int
    udp_drops: int
    cpu: dict[str, float]
    rss_before_kb: int
    rss_after_kb: int
    wall: float
    faults: int = 0
    """Minor page faults of the server during the flood."""
    sent_at: list[int] = field(default_factory=list)
    """Each packet's ``sendto`` (monotonic ns)."""
    stamps: Path | None = None
    """The server's stage stamps (``--trace``)."""
    profile: Path | None = None
    """The server's profile of the flood (``--profile``)."""
    costs: Path | None = None
    """The CPU of the server's loop callbacks during the flood (``--costs``)."""
    threads: dict[str, float] = field(default_factory=dict)
    """CPU seconds of each thread of the server during the flood."""
    dwell_ms: int = 0
    """The server's ``--relay-dwell``: 0 for the latency floods (each packet's command is
    matched), the default for the relay-wear run."""
    relay_changes: int = 0
    """Changes of the closed relays on the emulated boxes during the flood."""
    line_bytes: int = 0
    """Bytes the server wrote to the boxes during the flood (pings included)."""


async def bench_flood(name: str, rate: int, seconds: float, work: Path,
                      trace: bool = False, dwell_ms: int = 0,
                      profile: bool = False, costs: bool = False,
                      extra: Sequence[str] = (), idle: bool = False,
                      bare: bool = False) -> FloodResult:
    """A flood of ``rate`` packets a second for ``seconds`` into a headless server on
    emulated switches; ``idle``: no packets, the server's own CPU over ``seconds``;
    ``bare``: into the bare path (``quiet_path.bare``) instead of the server."""
    from moas_gui.config import load_config
    from moas_gui.hw.moas2.emulator.box import EmulatedBox, Traffic
    from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, make_link, serve

    loop = asyncio.get_running_loop()
    config = load_config(FLOODS[name].config).unwrap()
    terminals: dict[int, Terminal] = {}
    links: dict[int, Path] = {}
    for switch in config.switches:
        box, endpoint = EmulatedBox(), PtyEndpoint()
        serve(box, endpoint, loop)
        links[switch.id] = work / f"moas-switch-{name}-{rate}-{switch.id}"
        make_link(endpoint.path, links[switch.id])
        terminal = Terminal(switch.id, box, endpoint)

        def stamp(traffic: Traffic, data: bytes, t: Terminal = terminal) -> None:
            if traffic is Traffic.RECEIVED:
                t.reads.append((time.monotonic_ns(), data))

        box.add_listener(stamp)
        terminals[switch.id] = terminal
    stderr = work / f"flood-{name}-{rate}{'-'.join(('',) + tuple(extra))}.log"
    env = child_env(work / "settings", False)
    stamps = work / f"stamps-{name}-{rate}.json"
    if trace:
        env[quiet_path.TRACE_ENV] = str(stamps)
    profiled = work / f"profile-{name}-{rate}.pstats"
    if profile:
        env[quiet_path.PROFILE_ENV] = str(profiled)
    counted = work / f"costs-{name}-{rate}.json"
    if costs:
        env[quiet_path.COSTS_ENV] = str(counted)
    if bare:
        with stderr.open("wb") as err:
            process = await asyncio.create_subprocess_exec(
                sys.executable, __file__, "--bare", str(flood_config(name, work, links)),
                stdout=asyncio.subprocess.PIPE, stderr=err, env=env, cwd=str(ROOT))
    else:
        process, _ = await spawn_server(
            server_args(flood_config(name, work, links), True)
            + ["--log-level", "info", "--relay-dwell", str(dwell_ms), *extra], env, stderr)
    try:
        await read_marks(process, {"opened"}, timeout=30)
        found = None
        for _ in range(100):
            found = re.search(r"N1MM Logger on UDP 127\.0\.0\.1:(\d+)", stderr.read_text())
            if found:
                break
            await asyncio.sleep(0.05)
        if found is None:
            raise RuntimeError("the server did not listen for N1MM:\n" + stderr.read_text()[-3000:])
        for _ in range(200):
            if all(t.box.view().active for t in terminals.values()):
                break
            await asyncio.sleep(0.05)
        else:
            raise RuntimeError("the switches were never loaded:\n" + stderr.read_text()[-3000:])
        if idle:
            result = await _idle(name, seconds, process, profile or costs)
        else:
            result = await _flood(name, rate, seconds, int(found.group(1)), process,
                                  terminals, config, dwell_ms, profile or costs)
    finally:
        await stop(process)
        for terminal in terminals.values():
            terminal.endpoint.close()
            terminal.box.close()
        for link in links.values():
            link.unlink(missing_ok=True)
    if trace and stamps.exists():
        result.stamps = stamps
    if profile and profiled.exists():
        result.profile = profiled
    if costs and counted.exists():
        result.costs = counted
    return result


async def _flood(name: str, rate: int, seconds: float, port: int,
                 process: asyncio.subprocess.Process, terminals: dict[int, Terminal],
                 config: Any, dwell_ms: int = 0, signal_usr: bool = False) -> FloodResult:
    from moas_gui.hw.moas2.emulator.record import EntryCause
    from moas_gui.sources.n1mm_packet import radio_info_packet

    flood = FLOODS[name]
    # Every radio first goes to the last frequency of its cycle, so that the first
    # packet of the flood is already a change.
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        for ref in sorted(flood.cycles):
            udp.sendto(radio_info_packet(ref[1], flood.cycles[ref][-1]), ("127.0.0.1", port))
    await asyncio.sleep(1.0)
    for terminal in terminals.values():
        terminal.reads.clear()
    record_before = {i: t.box.record.written for i, t in terminals.items()}

    count = int(rate * seconds)
    rss_before = proc_status(process.pid).get("VmRSS", 0)
    before = {"server": cpu_seconds(process.pid), "emulators": own_cpu(),
              "machine": machine_busy()}
    faults_before = minor_faults(process.pid)
    threads_before = quiet_path.thread_cpu(process.pid)
    if signal_usr:  # the profiler or the callback costs start
        process.send_signal(signal.SIGUSR1)
    sender = await asyncio.create_subprocess_exec(
        sys.executable, __file__, "--send", str(port),
        json.dumps({"flood": name, "rate": rate, "count": count}),
        stdout=subprocess.PIPE, cwd=str(ROOT))
    queue_max = drops = 0
    sender_cpu = 0.0
    reader = asyncio.ensure_future(sender.communicate())
    while not reader.done():
        queued, drops = udp_queue(port)
        queue_max = max(queue_max, queued)
        sender_cpu = max(sender_cpu, cpu_seconds(sender.pid))
        await asyncio.wait([reader], timeout=0.25)
    stdout, _ = reader.result()
    await asyncio.sleep(0.5)
    threads_after = quiet_path.thread_cpu(process.pid)
    if signal_usr:
        process.send_signal(signal.SIGUSR2)
        await asyncio.sleep(0.5)
    cpu = {"server": cpu_seconds(process.pid) - before["server"],
           "emulators": own_cpu() - before["emulators"], "sender": sender_cpu,
           "machine": machine_busy() - before["machine"]}
    rss_after = proc_status(process.pid).get("VmRSS", 0)
    faults = minor_faults(process.pid) - faults_before
    sent: list[int] = json.loads(stdout)
    relay_changes = sum(1 for i, t in terminals.items()
                        for entry in t.box.record.after(record_before[i])
                        if entry.event is EntryCause.RELAYS)
    line_bytes = sum(len(data) for t in terminals.values() for _, data in t.reads)

    packets = flood_packets(flood, count)
    expected = expected_commands(flood, packets)
    # with a dwell, packets in a dwell cause no command of their own: nothing to match
    latencies = {} if dwell_ms else match(sent, packets, expected, terminals, config)
    per_second = []
    for second in range(int(seconds)):
        numbers = range(second * rate, min((second + 1) * rate, count))
        chunk = [latencies[s] for s in numbers if s in latencies]
        per_second.append((len(chunk), sum(1 for s in numbers if expected[s]), pct(chunk, 99)))
    antenna_bytes = {switch_id: sum(len(text) for _, text in t.commands() if text[0] != "'")
                     for switch_id, t in terminals.items()}
    return FloodResult(
        name=name, rate=rate, sent=count, expected=sum(1 for e in expected if e),
        latencies=latencies, per_second=per_second,
        bytes_per_change={s: b / max(1, len(latencies)) for s, b in antenna_bytes.items()},
        udp_queue_max=queue_max, udp_drops=drops, cpu=cpu, rss_before_kb=rss_before,
        rss_after_kb=rss_after, wall=(sent[-1] - sent[0]) / 1e9, sent_at=sent,
        faults=faults, dwell_ms=dwell_ms, relay_changes=relay_changes, line_bytes=line_bytes,
        threads={k: v - threads_before.get(k, 0.0) for k, v in threads_after.items()})


async def _idle(name: str, seconds: float, process: asyncio.subprocess.Process,
                signal_usr: bool) -> FloodResult:
    """The server with its switches loaded and no packet: its CPU over ``seconds``."""
    await asyncio.sleep(1.0)
    before = cpu_seconds(process.pid)
    threads_before = quiet_path.thread_cpu(process.pid)
    if signal_usr:
        process.send_signal(signal.SIGUSR1)
    await asyncio.sleep(seconds)
    threads_after = quiet_path.thread_cpu(process.pid)
    cpu = {"server": cpu_seconds(process.pid) - before}
    if signal_usr:
        process.send_signal(signal.SIGUSR2)
        await asyncio.sleep(0.5)
    return FloodResult(
        name=name, rate=0, sent=0, expected=0, latencies={}, per_second=[],
        bytes_per_change={}, udp_queue_max=0, udp_drops=0, cpu=cpu, rss_before_kb=0,
        rss_after_kb=0, wall=seconds,
        threads={k: v - threads_before.get(k, 0.0) for k, v in threads_after.items()})


def idle_rows(result: FloodResult) -> list[Row]:
    """What the server costs with nothing to do, a second and shared among band changes
    at the quiet rate (the flood's figure counts it too)."""
    per_second = result.cpu["server"] / max(result.wall, 1e-9)
    rows: list[Row] = [(
        f"idle server ({result.name}), no packets for {result.wall:g} s",
        (f"{1e3 * per_second:.2f} ms of CPU a second: {1e3 * per_second / QUIET_RATE:.2f} ms "
         f"of each band change at {QUIET_RATE}/s"), "", "")]
    for name, seconds in sorted(result.threads.items(), key=lambda item: -item[1]):
        rows.append((f"  thread {name}", f"{1e3 * seconds / result.wall:.2f} ms a second",
                     "", ""))
    return rows


LINE_BYTES_PER_SECOND = 960
"""9600 baud, 8N1: ten bits a byte."""


def wear_rows(result: FloodResult, without: FloodResult | None) -> list[Row]:
    """Relay operations and line use under a flood, with the relay dwell (and, from the
    latency run of the same flood and rate, without it)."""
    wall = max(result.wall, 1e-9)
    # each switch's relays move at most once a dwell for each flooded radio's station
    radios = max(1, len(FLOODS[result.name].cycles))
    bound = 1000 / result.dwell_ms * radios * max(1, len(result.bytes_per_change))
    rows: list[Row] = [(
        f"Relay wear, N1MM flood {result.rate}/s: {FLOODS[result.name].title}",
        f"relay dwell {result.dwell_ms} ms (the server's default)", "", "")]
    ops = result.relay_changes / wall
    rows.append(("  relay-state changes a second", f"{ops:.1f}",
                 f"<= {bound:.0f} (once a dwell a radio a switch)", _verdict(ops <= bound * 1.05)))
    rows.append(("  line use (9600 baud)",
                 f"{100 * result.line_bytes / wall / LINE_BYTES_PER_SECOND:.0f} %", "", ""))
    if without is not None:
        w = max(without.wall, 1e-9)
        rows.append(("  the same flood without the dwell",
                     (f"{without.relay_changes / w:.1f} relay-state changes a second, line "
                      f"{100 * without.line_bytes / w / LINE_BYTES_PER_SECOND:.0f} %"), "", ""))
    return rows


def flood_rows(result: FloodResult) -> list[Row]:
    lat = [result.latencies[s] for s in sorted(result.latencies)]
    answered = len(lat)
    rows: list[Row] = [
        (f"N1MM flood {result.rate}/s: {FLOODS[result.name].title}",
         (f"{result.sent} packets in {result.wall:.1f} s; of {result.expected} that change "
         f"antennas {answered} did, {result.expected - answered} not (kernel dropped "
         f"{result.udp_drops})"),
         "all", _verdict(answered == result.expected)),
    ]
    if not lat:
        return rows
    rows.append(("  packet sent -> first byte at the switch",
                 (f"median {statistics.median(lat):.2f} ms, p90 {pct(lat, 90):.2f} ms, "
                 f"p99 {pct(lat, 99):.2f} ms, max {max(lat):.2f} ms"), "p99 < 5 ms",
                 _verdict(pct(lat, 99) < 5.0)))
    counts = [n for n, _, _ in result.per_second]
    p99s = [p99 for _, _, p99 in result.per_second]
    rows.append(("  each second: packets answered", " ".join(str(n) for n in counts), "all",
                 _verdict(all(n == due for n, due, _ in result.per_second))))
    rows.append(("  each second: p99 (ms)", " ".join(f"{p:.1f}" for p in p99s), "flat",
                 _verdict(max(p99s) < 5.0)))
    rows.append(("  kernel UDP receive queue, largest", f"{result.udp_queue_max} bytes", "", ""))
    cpu, wall = result.cpu, result.wall
    others = max(0.0, cpu["machine"] - cpu["server"] - cpu["emulators"] - cpu["sender"])
    rows.append(("  CPU, % of one core",
                 (f"server {100 * cpu['server'] / wall:.0f}, emulated switches "
                 f"{100 * cpu['emulators'] / wall:.0f}, sender {100 * cpu['sender'] / wall:.0f}, "
                 f"other programs {100 * others / wall:.0f} (of {100 * (os.cpu_count() or 1)})"),
                 "", ""))
    rows.append(("  server CPU per packet",
                 f"{1000 * cpu['server'] / result.sent:.2f} ms", "", ""))
    rows.append(("  server minor page faults per packet",
                 f"{result.faults / result.sent:.1f}", "", ""))
    rows.append(("  server RSS before / after",
                 f"{result.rss_before_kb / 1024:.0f} MB / {result.rss_after_kb / 1024:.0f} MB",
                 "< 150 MB", _verdict(result.rss_after_kb / 1024 < 150)))
    per_switch = sorted(result.bytes_per_change.items())
    rows.append(("  bytes on the wire per antenna change",
                 ", ".join(f"switch {s}: {b:.1f}" for s, b in per_switch), "", ""))
    return rows


# --------------------------------------------------------------------------- (c) bytes


def bytes_rows() -> list[Row]:
    """Bytes the link writes for band changes on the big station (its planner's count)."""
    from moas_gui.config import load_config
    from moas_gui.engine import Engine
    from moas_gui.hw.moas2.sync import count_bytes

    engine = Engine(load_config(BIG).unwrap())
    for station, khz in ((1, 14025.0), (2, 21025.0)):
        engine.set_frequency(station, 1, khz)
    rows = []
    moves = [(1, 14025.0, 7025.0), (1, 7025.0, 3525.0), (1, 3525.0, 1825.0),
             (2, 21025.0, 28025.0), (2, 28025.0, 14225.0)]
    for station, before_khz, after_khz in moves:
        before = engine.switch_states()
        after = {**before, **engine.set_frequency(station, 1, after_khz).switches}
        counts = [f"switch {sid}: {count_bytes(before[sid], after[sid])}" for sid in sorted(before)]
        rows.append(((f"bytes, big-station radio {station}/1 {_band(before_khz)} -> "
                     f"{_band(after_khz)}"), ", ".join(counts), "", ""))
    return rows


def _band(khz: float) -> str:
    for low, name in ((28000, "10 m"), (21000, "15 m"), (14000, "20 m"), (7000, "40 m"),
                      (3500, "80 m"), (1800, "160 m")):
        if khz >= low:
            return name
    return f"{khz:.0f} kHz"


# --------------------------------------------------------------------------- (d) the parts


def band_change_parts(name: str, changes: int = 3000) -> dict[str, float]:
    """The parts of the server's work for a band change, each timed alone in this process
    (CPU seconds per change, ``time.process_time``): parse, engine decision, switch plan."""
    from moas_gui.config import load_config
    from moas_gui.engine import Engine
    from moas_gui.hw.moas2.sync import difference
    from moas_gui.sources.n1mm_packet import parse_radio_info, radio_info_packet

    flood = FLOODS[name]
    steps = flood_packets(flood, changes)
    packets = [radio_info_packet(ref[1], khz) for ref, khz in steps]
    clock = time.process_time
    started = clock()
    for packet in packets:
        parse_radio_info(packet)
    parse = clock() - started

    engine = Engine(load_config(flood.config).unwrap())
    states = engine.switch_states()
    started = clock()
    decided = [engine.set_frequency(*ref, khz, now=n / 1000).switches
               for n, (ref, khz) in enumerate(steps)]
    decide = clock() - started
    started = clock()
    for switches in decided:
        for switch_id, state in switches.items():
            difference(states[switch_id], state).encode()
            states[switch_id] = state
    plan = clock() - started
    return {"parse RadioInfo": parse / changes, "engine decision": decide / changes,
            "switch plan and bytes": plan / changes}


def cost_rows(name: str, parts: dict[str, float]) -> list[Row]:
    text = ", ".join(f"{part} {1e6 * seconds:.0f} us" for part, seconds in parts.items())
    return [(f"parts of a band change ({name}), timed alone",
             f"{text}; together {1e6 * sum(parts.values()):.0f} us", "", "")]


QUIET_CPU_RATIO = 5.0
"""Server CPU per quiet band change, at most this many times the parts timed alone."""
QUIET_FLOOR_MS = 0.6
"""Packet to first byte at the quiet rate (median), at most this much above the floor's."""


def target_rows(quiet: list[FloodResult], parts: dict[str, dict[str, float]],
                floors: dict[int, list[float]],
                title: str = "The quiet path's targets (this run)") -> list[Row]:
    """The quiet path's two targets (issue 33), each from figures of this one run."""
    rows: list[Row] = [(title, "", "", "")]
    for result in quiet:
        label = f"{result.name} {result.rate}/s"
        if result.name in parts:
            alone = sum(parts[result.name].values())
            per_change = result.cpu["server"] / max(1, result.sent)
            ratio = per_change / alone
            rows.append((f"  server CPU per band change / the parts alone ({label})",
                         (f"{1e3 * per_change:.2f} ms / {1e3 * alone:.2f} ms = "
                          f"{ratio:.1f} x"),
                         f"<= {QUIET_CPU_RATIO:g} x", _verdict(ratio <= QUIET_CPU_RATIO)))
        lat = list(result.latencies.values())
        floor = floors.get(result.rate)
        if not lat:
            continue
        if not floor:
            rows.append((f"  packet to first byte above the floor ({label})",
                         "no floor measured: run with --floor",
                         f"<= {QUIET_FLOOR_MS:g} ms", ""))
            continue
        above = statistics.median(lat) - statistics.median(floor)
        rows.append((f"  packet to first byte above the floor ({label}, medians)",
                     (f"{statistics.median(lat):.2f} ms - {statistics.median(floor):.2f} ms"
                      f" = {above:.2f} ms"),
                     f"<= {QUIET_FLOOR_MS:g} ms", _verdict(above <= QUIET_FLOOR_MS)))
    return rows


def antenna_log_rows(on: FloodResult, off: FloodResult) -> list[Row]:
    """The antenna log's cost on the quiet path: the same flood with it on (the default)
    and with ``--no-antenna-log``, in this one run (issue 34: it stays off the path)."""
    def figures(result: FloodResult) -> tuple[float, float]:
        lat = list(result.latencies.values())
        return (statistics.median(lat) if lat else float("nan"),
                1e3 * result.cpu["server"] / max(1, result.sent))

    (lat_on, cpu_on), (lat_off, cpu_off) = figures(on), figures(off)
    label = f"{on.name} {on.rate}/s"
    return [
        (f"Antenna log on / off ({label})", "", "", ""),
        ("  packet to first byte, median",
         f"{lat_on:.2f} ms / {lat_off:.2f} ms ({lat_on - lat_off:+.2f} ms)", "", ""),
        ("  server CPU per packet",
         f"{cpu_on:.2f} ms / {cpu_off:.2f} ms ({cpu_on - cpu_off:+.2f} ms)", "", ""),
    ]


# --------------------------------------------------------------------------- main


async def floor_latencies(rates: Sequence[int], seconds: float
                          ) -> tuple[dict[int, list[float]], dict[int, float]]:
    """The machine's floor at each rate: the same hops with nothing done between them; and
    the middle process's CPU seconds per packet at each rate."""
    latencies: dict[int, list[float]] = {}
    hops: dict[int, float] = {}
    for rate in rates:
        latencies[rate], hops[rate] = await quiet_path.floor(Path(__file__), ROOT, rate, seconds)
    return latencies, hops


def floor_rows(floors: dict[int, list[float]], hops: dict[int, float]) -> list[Row]:
    rows: list[Row] = []
    for rate, lat in floors.items():
        if lat:
            rows.append((f"floor {rate}/s: UDP -> an asyncio process -> a pseudo-terminal",
                         (f"median {statistics.median(lat):.2f} ms, p90 {pct(lat, 90):.2f} ms, "
                          f"p99 {pct(lat, 99):.2f} ms ({len(lat)} packets); the middle "
                          f"process's CPU {1e3 * hops[rate]:.2f} ms a packet"), "", ""))
    return rows


def print_table(rows: list[Row]) -> None:
    width = [max(len(r[i]) for r in rows) for i in range(4)]
    head = ("measure", "figure", "target", "")
    print("  ".join(h.ljust(w) for h, w in zip(head, width, strict=True)).rstrip())
    print("  ".join("-" * w for w in width))
    for row in rows:
        print("  ".join(c.ljust(w) for c, w in zip(row, width, strict=True)).rstrip())


async def run(args: argparse.Namespace) -> None:
    print(f"Machine: {machine()}")
    rows: list[Row] = []
    quiet: list[FloodResult] = []
    bare: list[FloodResult] = []
    floors: dict[int, list[float]] = {}
    with tempfile.TemporaryDirectory(prefix="bench-server-") as folder:
        work = Path(folder)
        (work / "settings").mkdir()
        if args.runs:
            rows += await bench_start(args.runs, not args.no_window, work)
        for name in args.flood if args.idle else ():
            result = await bench_flood(name, 0, args.idle, work, costs=args.costs,
                                       idle=True)
            rows += idle_rows(result)
            if result.costs is not None:  # per second: "changes" are the seconds
                rows += quiet_path.costs_rows(result.costs, round(args.idle), 0,
                                              result.threads, per="second")
        for name in args.flood:
            for rate in args.rate:
                result = await bench_flood(name, rate, args.seconds, work, args.trace,
                                           profile=bool(args.profile) and rate <= QUIET_RATE,
                                           costs=args.costs)
                rows += flood_rows(result)
                if rate <= QUIET_RATE:
                    quiet.append(result)
                    if args.bare:
                        alone = await bench_flood(name, rate, args.seconds, work, bare=True)
                        rows += [(f"bare path: {label}", text, target, verdict)
                                 for label, text, target, verdict in flood_rows(alone)[:2]]
                        rows.append(("  bare path CPU per packet",
                                     f"{1000 * alone.cpu['server'] / alone.sent:.2f} ms", "", ""))
                        bare.append(alone)
                    if args.antenna_log:
                        off = await bench_flood(name, rate, args.seconds, work,
                                                extra=["--no-antenna-log"])
                        rows += antenna_log_rows(result, off)
                if rate == max(args.rate) and args.dwell:
                    worn = await bench_flood(name, rate, args.seconds, work,
                                             dwell_ms=args.dwell)
                    rows += wear_rows(worn, result)
                if result.stamps is not None and rate <= QUIET_RATE:
                    rows += quiet_path.stage_rows(result.stamps, result.sent_at,
                                                  result.latencies, rate)
                if result.costs is not None:
                    rows += quiet_path.costs_rows(result.costs, result.sent, rate,
                                                  result.threads)
                if result.profile is not None:
                    rows += quiet_path.profile_rows(result.profile, result.sent, rate)
                    if args.profile != "-":
                        shutil.copyfile(result.profile, args.profile)
        if args.floor:
            floors, hops = await floor_latencies(args.rate, args.seconds)
            rows += floor_rows(floors, hops)
    parts = {name: band_change_parts(name) for name in ("small", "big")}
    for name, timed in parts.items():
        rows += cost_rows(name, timed)
    rows += bytes_rows()
    rows += target_rows(quiet, parts, floors)
    if bare:
        rows += target_rows(bare, parts, floors, "The bare path against the same targets: "
                            "the floor's hops with only the parts between them")
    print_table(rows)
    print(f"Load average after: {_load()}")


def _names(text: str) -> list[str]:
    names = [n for n in text.split(",") if n]
    unknown = [n for n in names if n not in FLOODS]
    if unknown:
        raise argparse.ArgumentTypeError(f"unknown flood {', '.join(unknown)}; "
                                         f"choose from {', '.join(FLOODS)}")
    return names


def main() -> int:
    if len(sys.argv) > 1 and sys.argv[1] == "--serve":
        return serve_child(sys.argv[2:])
    if len(sys.argv) > 1 and sys.argv[1] == "--send":
        send(int(sys.argv[2]), sys.argv[3])
        return 0
    if len(sys.argv) > 1 and sys.argv[1] == "--bare":
        quiet_path.bare(sys.argv[2], MARK)
        return 0
    if len(sys.argv) > 1 and sys.argv[1] == "--relay":
        quiet_path.relay(sys.argv[2])
        return 0
    if len(sys.argv) > 1 and sys.argv[1] == "--floor-send":
        quiet_path.send_numbers(*(int(x) for x in sys.argv[2:5]))
        return 0
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3,
                        help="start-ups of each kind (default 3; 0 skips them)")
    parser.add_argument("--rate", type=lambda text: [int(x) for x in text.split(",")],
                        default=[QUIET_RATE, 1000],
                        help="N1MM packets a second; several: 10,250,1000 (default 10,1000)")
    parser.add_argument("--trace", action="store_true",
                        help="also print where a quiet packet's time goes (benchmarks/"
                             "quiet_path.py: the server stamps each stage)")
    parser.add_argument("--costs", action="store_true",
                        help="also print the server's CPU per band change by thread and by "
                             "event-loop callback (about a microsecond of overhead a callback)")
    parser.add_argument("--profile", nargs="?", const="-", default=None, metavar="FILE",
                        help="also profile the server (cProfile, its event loop's thread) "
                             "during each quiet flood and print the costliest functions per "
                             "band change (the profiler's overhead makes the flood's own "
                             "figures worth less: take them without it); FILE: also keep the "
                             "profile there (pstats)")
    parser.add_argument("--floor", action="store_true",
                        help="also measure the machine's floor at each rate: the same hops "
                             "with no work between them")
    parser.add_argument("--bare", action="store_true",
                        help="also run each quiet flood into the bare path: the floor's hops "
                             "with only the parts between them (parse, engine, plan, write; "
                             "quiet_path.bare), what any server on these parts must spend")
    parser.add_argument("--seconds", type=float, default=10.0, help="length of each flood")
    parser.add_argument("--idle", type=float, default=0.0, metavar="SECONDS",
                        help="also measure each flood's server with no packets for SECONDS "
                             "(its own periodic work; with --costs, by loop callback, per "
                             "second)")
    parser.add_argument("--antenna-log", action="store_true",
                        help="also run each quiet flood with --no-antenna-log and print what "
                             "the antenna log costs on the path (issue 34)")
    parser.add_argument("--flood", type=_names, default=list(FLOODS),
                        help=f"floods to run, of {','.join(FLOODS)} (default all)")
    parser.add_argument("--no-window", action="store_true", help="skip the window start-ups")
    parser.add_argument("--dwell", type=int, default=100, metavar="MS",
                        help="the relay dwell of the relay-wear run, at the highest rate of "
                             "each flood (default 100, the server's; 0 skips it); the latency "
                             "floods run with --relay-dwell 0, so that every packet's command "
                             "can be matched")
    asyncio.run(run(parser.parse_args()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
