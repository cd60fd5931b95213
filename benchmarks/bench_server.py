"""The server's speed targets, measured on the real program as a station runs it.

Run:  .venv/bin/python benchmarks/bench_server.py [--runs 3] [--rate 1000] [--seconds 10]
                                                  [--flood small|big|both] [--no-window]

Prints one table with:

(a) **Start-up and memory.**  ``moas-server examples/big-station.moas`` as a
    separate process, with the window (``QT_QPA_PLATFORM=offscreen``) and
    headless.  Measured from just before the process is spawned to the log
    record "Opened big-station.moas ..." (the configuration runs, the window
    title and status bar name the file), and for the window also to the
    moment its status bar shows every switch answering.  Resident memory
    (VmRSS from ``/proc/PID/status``) one second after "Opened", and the
    peak (VmHWM).  Targets: start < 2 s, RSS < 150 MB.
(b) **N1MM Logger flood.**  A sender process plays N1MM Logger+ at 1,000
    RadioInfo packets a second for 10 s over real UDP on 127.0.0.1 into
    ``moas-server --headless``; every packet moves one of two radios to
    another band, so every packet makes the engine choose another antenna.
    The switches are emulated boxes on pseudo-terminals served by *this*
    process, which timestamps every read from the terminal.  The k-th
    antenna command (``!<station>...;``) for a radio's switch port answers
    that radio's k-th packet; the time from ``sendto`` in the sender to the
    arrival of that command's first byte is the latency (both processes read
    CLOCK_MONOTONIC).  Target: p99 < 5 ms, with per-second p99 and counts
    flat (no backlog).  ``small``: the SO2R small station, radios 1 and 2 of
    one N1MM computer on one switch.  ``big``: the big station, station 1
    (the one whose N1MM computer is 127.0.0.1) on its two switches.
(c) **Bytes on the wire** for band changes on the big station, from the
    switch link's own planner, and as counted on the terminals in (b).

How the server is started: ``python bench_server.py --serve ARGS`` runs
``moas_gui.cli.server.main(ARGS)`` after two additions that change nothing
measured: the N1MM socket is bound to the ``--bind`` address (127.0.0.1)
instead of every address, and a logging handler prints a marker line with
the monotonic clock when "Opened ..." is logged.  Every run uses
``--new-instance`` (never hands the file to a server that is already
running), free ports and a throw-away settings folder.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import logging
import os
import platform
import re
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
EXAMPLES = ROOT / "examples"
BIG = EXAMPLES / "big-station.moas"
SMALL = EXAMPLES / "small-station.moas"
MARK = "BENCH-MARK"

# The bands each flooded radio runs through, one step per packet: three bands whose
# antenna commands differ, never the same band on two radios at once.
CYCLE = 3
BANDS: dict[str, dict[tuple[int, int], tuple[float, ...]]] = {
    "small": {(1, 1): (14025.0, 7025.0, 28025.0), (1, 2): (21025.0, 3525.0, 7125.0)},
    "big": {(1, 1): (14025.0, 7025.0, 21025.0)},
}
CONFIGS = {"small": SMALL, "big": BIG}
Row = tuple[str, str, str, str]
"""One line of the table: measure, figure, target, verdict."""

sys.path.insert(0, str(ROOT))


# --------------------------------------------------------------------------- the child


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
        if self.window:
            from PySide6.QtCore import QTimer

            QTimer.singleShot(0, self._watch_window)

    def _watch_window(self) -> None:
        """Mark when the window names the file, then when every switch answers."""
        from PySide6.QtCore import QTimer
        from PySide6.QtWidgets import QApplication, QMainWindow

        windows = [w for w in QApplication.topLevelWidgets() if isinstance(w, QMainWindow)]
        shown = [w for w in windows if w.windowTitle().endswith(" - MOAS Server")]
        if not shown:
            QTimer.singleShot(5, self._watch_window)
            return
        print(f"{MARK} shown {time.monotonic_ns()} {shown[0].windowTitle()}", flush=True)
        self._watch_switches(shown[0], time.monotonic() + 10)

    def _watch_switches(self, window: object, give_up: float) -> None:
        from PySide6.QtCore import QTimer

        text = window.statusBar().currentMessage()  # type: ignore[attr-defined]
        if "switch" in text and "connecting" not in text and "unresponsive" not in text:
            print(f"{MARK} ready {time.monotonic_ns()} {text}", flush=True)
        elif time.monotonic() < give_up:
            QTimer.singleShot(5, lambda: self._watch_switches(window, give_up))


def serve_child(argv: list[str]) -> int:
    """``moas-server ARGS`` with the N1MM socket on the loopback address and an "Opened" marker."""
    import dataclasses

    from moas_gui.cli import server as cli

    original = cli._options

    def loopback_options(args: argparse.Namespace) -> object:
        return dataclasses.replace(original(args), udp_bind=args.bind)  # type: ignore[type-var]

    cli._options = loopback_options  # type: ignore[assignment]
    logging.getLogger("moas_gui.app").addHandler(_MarkHandler(window="--headless" not in argv))
    return cli.main(argv)


# --------------------------------------------------------------------------- the sender


def send(port: int, plan_json: str) -> None:
    """The N1MM Logger process: paced RadioInfo packets, then their send times as JSON."""
    from moas_gui.net.n1mm_packet import radio_info_packet

    plan = json.loads(plan_json)
    rate = plan["rate"]
    radios = [(radio, tuple(bands)) for radio, bands in plan["radios"]]
    packets = [radio_info_packet(radio, khz, station_name="BENCH-PC")
               for radio, khz in flood_packets(radios, plan["count"])]
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sent = [0] * len(packets)
    start = time.monotonic() + 0.1
    for seq, data in enumerate(packets):
        due = start + seq / rate
        delay = due - time.monotonic()
        if delay > 0:
            time.sleep(delay)  # no busy wait: the two cores belong to the server and the switches
        sent[seq] = time.monotonic_ns()
        sock.sendto(data, ("127.0.0.1", port))
    print(json.dumps(sent))


# --------------------------------------------------------------------------- helpers


def flood_packets(radios: list[tuple[int, tuple[float, ...]]],
                  count: int) -> list[tuple[int, float]]:
    """(radio number, kHz) of each flood packet: the radios in turn, each on its next band."""
    return [(radios[s % len(radios)][0],
             radios[s % len(radios)][1][(s // len(radios)) % len(radios[s % len(radios)][1])])
            for s in range(count)]


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


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of ``pid`` so far."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def own_cpu() -> float:
    """CPU seconds of this process (the emulated switches, and little else during a flood)."""
    usage = os.times()
    return usage.user + usage.system


def machine_busy() -> float:
    """CPU seconds every core of the machine spent busy so far (from /proc/stat)."""
    try:
        fields = [int(x) for x in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]]
    except (OSError, ValueError):
        return 0.0
    idle = fields[3] + (fields[4] if len(fields) > 4 else 0)
    return (sum(fields[:8]) - idle) / os.sysconf("SC_CLK_TCK")


def udp_queue(port: int) -> tuple[int, int]:
    """(receive-queue bytes, drops) of the UDP socket bound to ``port``."""
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
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    model = ""
    try:
        model = next(line.split(":", 1)[1].strip()
                     for line in Path("/proc/cpuinfo").read_text().splitlines()
                     if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return (f"{os.cpu_count()} cores ({model or platform.machine()}), load average {load}, "
            f"Python {platform.python_version()}")


def child_env(settings: Path, window: bool) -> dict[str, str]:
    env = dict(os.environ, PYTHONUNBUFFERED="1", XDG_CONFIG_HOME=str(settings))
    if window:
        env["QT_QPA_PLATFORM"] = "offscreen"
    return env


async def spawn_server(args: list[str], env: dict[str, str], stderr: Path) -> tuple[
        asyncio.subprocess.Process, int]:
    started = time.monotonic_ns()
    with stderr.open("wb") as err:
        process = await asyncio.create_subprocess_exec(
            sys.executable, __file__, "--serve", *args,
            stdout=asyncio.subprocess.PIPE, stderr=err, env=env, cwd=str(ROOT))
    return process, started


async def read_marks(process: asyncio.subprocess.Process, wanted: set[str],
                     timeout: float) -> dict[str, int]:
    """Marker name -> monotonic ns, until every name in ``wanted`` came (or the timeout)."""
    assert process.stdout is not None
    marks: dict[str, int] = {}
    loop = asyncio.get_running_loop()
    end = loop.time() + timeout
    while not wanted <= marks.keys():
        try:
            line = await asyncio.wait_for(process.stdout.readline(), max(0.01, end - loop.time()))
        except TimeoutError:
            break
        if not line:
            break
        parts = line.decode(errors="replace").split(maxsplit=3)
        if len(parts) >= 3 and parts[0] == MARK:
            marks[parts[1]] = int(parts[2])
    return marks


async def stop(process: asyncio.subprocess.Process) -> None:
    if process.returncode is None:
        process.send_signal(signal.SIGTERM)
        try:
            await asyncio.wait_for(process.wait(), 10)
        except TimeoutError:
            process.kill()
            await process.wait()


def server_args(config: Path, headless: bool) -> list[str]:
    return [*(["--headless"] if headless else []), str(config), "--bind", "127.0.0.1",
            "--tcp-port", "0", "--udp-port", "0", "--no-rotator-program", "--new-instance"]


# --------------------------------------------------------------------------- (a)


@dataclass
class StartRun:
    opened_s: float
    shown_s: float | None
    ready_s: float | None
    open_ms: float
    rss_kb: int
    hwm_kb: int


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
        text = stderr.read_text(errors="replace")
        found = re.search(r"Opened big-station\.moas in (\d+) ms", text)
    finally:
        await stop(process)
    open_ms = float(found.group(1)) if found else float("nan")

    def since(name: str) -> float | None:
        return (marks[name] - started) / 1e9 if name in marks else None

    return StartRun(opened_s=since("opened") or 0.0, shown_s=since("shown"),
                    ready_s=since("ready"), open_ms=open_ms,
                    rss_kb=memory.get("VmRSS", 0), hwm_kb=memory.get("VmHWM", 0))


async def bench_start(runs: int, window: bool, work: Path) -> list[Row]:
    rows: list[Row] = []
    for headless in ([False] if window else []) + [True]:
        label = "headless" if headless else "window (offscreen)"
        results = [await start_once(headless, work) for _ in range(runs)]
        opened = [r.opened_s for r in results]
        rows.append((f"start to 'Opened', {label}",
                     f"median {statistics.median(opened):.2f} s, max {max(opened):.2f} s",
                     "< 2 s", _verdict(max(opened) < 2.0)))
        if not headless:
            shown = [r.shown_s for r in results if r.shown_s is not None]
            ready = [r.ready_s for r in results if r.ready_s is not None]
            if shown:
                rows.append(("  window title/status bar name the file",
                             f"median {statistics.median(shown):.2f} s, max {max(shown):.2f} s",
                             "< 2 s", _verdict(max(shown) < 2.0)))
            if ready:
                rows.append(("  status bar: both switches ok",
                             f"median {statistics.median(ready):.2f} s, max {max(ready):.2f} s",
                             "", ""))
        rows.append((f"  of which loading + starting the file ({label})",
                     f"median {statistics.median([r.open_ms for r in results]):.0f} ms", "", ""))
        rss = [r.rss_kb / 1024 for r in results]
        rows.append((f"resident memory 1 s after 'Opened', {label}",
                     f"{statistics.median(rss):.0f} MB (peak {max(r.hwm_kb for r in results) / 1024:.0f} MB)",
                     "< 150 MB", _verdict(max(rss) < 150)))
    return rows


def _verdict(ok: bool) -> str:
    return "PASS" if ok else "FAIL"


# --------------------------------------------------------------------------- (b)


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


def flood_config(kind: str, work: Path, links: dict[int, Path]) -> Path:
    """The example with its switches on the terminals and 127.0.0.1 as station 1's N1MM computer."""
    data = json.loads(CONFIGS[kind].read_text())
    for switch in data["Switches"]:
        switch["Port"] = str(links[switch["ID"]])
    data["UseN1MMLogger"] = True
    data["N1MMLogger"] = [{"Address": "127.0.0.1", "Station": 1}]
    data["StartMOASRotator"] = False
    path = work / f"flood-{kind}.moas"
    path.write_text(json.dumps(data, indent=1))
    return path


def switch_ports(config: Any, ref: tuple[int, int]) -> dict[int, int]:
    """Switch id -> the switch's station port of radio ``ref``."""
    only = config.switches[0].id if len(config.switches) == 1 else 0
    return {sp.switch or only: sp.port for sp in config.radio(*ref).switches}


def expected_commands(kind: str) -> dict[tuple[tuple[int, int], int], list[str]]:
    """(radio, switch) -> the antenna command each band of the radio's cycle sends that switch.

    Worked out with the engine and the link's planner in this process, the
    same code the server runs, so a command on the wire can be told apart
    from one that answers another packet.
    """
    from moas_gui.engine import Engine
    from moas_gui.engine.config import load_config
    from moas_gui.hw.moas2.sync import difference

    config = load_config(CONFIGS[kind]).unwrap()
    engine = Engine(config)
    states = engine.switch_states()
    cycles = BANDS[kind]
    found: dict[tuple[tuple[int, int], int], list[str]] = {}
    for lap in range(3):
        for step in range(CYCLE):
            for ref, bands in cycles.items():
                changes = engine.set_frequency(*ref, bands[step])
                for switch_id, state in changes.switches.items():
                    text = difference(states[switch_id], state).encode().decode("latin-1")
                    states[switch_id] = state
                    port = switch_ports(config, ref).get(switch_id)
                    if lap == 2 and port is not None:
                        mine = [c + ";" for c in text.split(";") if c.startswith(f"!{port}")]
                        found.setdefault((ref, switch_id), []).append(mine[0] if mine else "")
    return found


@dataclass
class FloodResult:
    kind: str
    rate: int
    sent: int
    latencies: dict[int, float]
    per_second: list[tuple[int, int, float, float]]
    bytes_per_change: dict[int, float]
    udp_queue_max: int
    udp_drops: int
    cpu: dict[str, float]
    rss_before_kb: int
    rss_after_kb: int
    wall: float


async def bench_flood(kind: str, rate: int, seconds: float, work: Path) -> FloodResult:
    from moas_gui.engine.config import load_config
    from moas_gui.hw.moas2.emulator.box import EmulatedBox, Traffic
    from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, make_link, serve

    loop = asyncio.get_running_loop()
    config = load_config(CONFIGS[kind]).unwrap()
    terminals: dict[int, Terminal] = {}
    links: dict[int, Path] = {}
    for switch in config.switches:
        box, endpoint = EmulatedBox(), PtyEndpoint()
        serve(box, endpoint, loop)
        links[switch.id] = work / f"moas-switch-{kind}-{rate}-{switch.id}"
        make_link(endpoint.path, links[switch.id])
        terminal = Terminal(switch.id, box, endpoint)

        def stamp(traffic: Traffic, data: bytes, t: Terminal = terminal) -> None:
            if traffic is Traffic.RECEIVED:
                t.reads.append((time.monotonic_ns(), data))

        box.add_listener(stamp)
        terminals[switch.id] = terminal
    path = flood_config(kind, work, links)
    stderr = work / f"flood-{kind}-{rate}.log"
    process, _ = await spawn_server(server_args(path, True) + ["--log-level", "info"],
                                    child_env(work / "settings", False), stderr)
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
        return await _flood(kind, rate, seconds, int(found.group(1)), process, terminals)
    finally:
        await stop(process)
        for terminal in terminals.values():
            terminal.endpoint.close()
            terminal.box.close()


async def _flood(kind: str, rate: int, seconds: float, port: int,
                 process: asyncio.subprocess.Process, terminals: dict[int, Terminal]) -> FloodResult:
    from moas_gui.engine.config import load_config
    from moas_gui.net.n1mm_packet import radio_info_packet

    config = load_config(CONFIGS[kind]).unwrap()
    cycles = BANDS[kind]
    radios = sorted(cycles)
    # Every radio first goes to the last band of its cycle, so that every flood packet,
    # starting with the first, moves it to another band.
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        for ref in radios:
            udp.sendto(radio_info_packet(ref[1], cycles[ref][-1]), ("127.0.0.1", port))
    await asyncio.sleep(1.0)
    for terminal in terminals.values():
        terminal.reads.clear()

    count = int(rate * seconds)
    plan = {"rate": rate, "count": count, "radios": [(ref[1], cycles[ref]) for ref in radios]}
    rss_before = proc_status(process.pid).get("VmRSS", 0)
    cpu_before = {"server": cpu_seconds(process.pid), "emulators": own_cpu(),
                  "machine": machine_busy()}
    sender = await asyncio.create_subprocess_exec(
        sys.executable, __file__, "--send", str(port), json.dumps(plan),
        stdout=subprocess.PIPE, cwd=str(ROOT))
    sender_pid = sender.pid
    queue_max = drops = 0
    sender_cpu = 0.0
    reader = asyncio.ensure_future(sender.communicate())
    while not reader.done():
        queued, drops = udp_queue(port)
        queue_max = max(queue_max, queued)
        sender_cpu = max(sender_cpu, cpu_seconds(sender_pid))
        await asyncio.wait([reader], timeout=0.25)
    stdout, _ = reader.result()
    await asyncio.sleep(0.5)
    cpu = {"server": cpu_seconds(process.pid) - cpu_before["server"],
           "emulators": own_cpu() - cpu_before["emulators"], "sender": sender_cpu,
           "machine": machine_busy() - cpu_before["machine"]}
    rss_after = proc_status(process.pid).get("VmRSS", 0)
    sent: list[int] = json.loads(stdout)
    latencies = match(sent, radios, terminals, expected_commands(kind), config)
    bytes_per_change = {
        switch_id: sum(len(text) for _, text in terminal.commands() if not text.startswith("'"))
        / max(1, len(latencies)) for switch_id, terminal in terminals.items()}
    per_second = []
    for second in range(int(seconds)):
        chunk = [latencies[s] for s in range(second * rate, min((second + 1) * rate, count))
                 if s in latencies]
        per_second.append((second + 1, len(chunk), pct(chunk, 50), pct(chunk, 99)))
    return FloodResult(
        kind=kind, rate=rate, sent=count, latencies=latencies, per_second=per_second,
        bytes_per_change=bytes_per_change, udp_queue_max=queue_max, udp_drops=drops, cpu=cpu,
        rss_before_kb=rss_before, rss_after_kb=rss_after, wall=(sent[-1] - sent[0]) / 1e9)


def match(sent: list[int], radios: list[tuple[int, int]], terminals: dict[int, Terminal],
          expected: dict[tuple[tuple[int, int], int], list[str]], config: Any) -> dict[int, float]:
    """Packet number -> ms from its ``sendto`` to the first byte of the command answering it.

    Packets go to the radios in turn, and each radio runs through a cycle of
    bands whose antenna commands differ.  Walking a radio's packets in order
    beside the commands its switch port received in order, a command answers
    the packet when it is the one that packet's band sends; a packet whose
    command is not next (the packet was dropped, or the server sent nothing)
    stays unanswered.  Exact while fewer than two packets of a radio in a row
    go missing; where a switch gets commands from several switches' worth of
    one packet, the earliest counts.
    """
    latencies: dict[int, float] = {}
    for index, ref in enumerate(radios):
        packets = range(index, len(sent), len(radios))
        for switch_id, port in switch_ports(config, ref).items():
            wanted = expected.get((ref, switch_id))
            if not wanted or not all(wanted) or switch_id not in terminals:
                continue
            got = [(at, text) for at, text in terminals[switch_id].commands()
                   if text.startswith(f"!{port}")]
            position = 0
            for k, seq in enumerate(packets):
                if position < len(got) and got[position][1] == wanted[k % CYCLE]:
                    delay = (got[position][0] - sent[seq]) / 1e6
                    latencies[seq] = min(delay, latencies.get(seq, delay))
                    position += 1
    return latencies


def flood_rows(result: FloodResult) -> list[Row]:
    lat = [result.latencies[s] for s in sorted(result.latencies)]
    name = {"small": "small-station, radios 1+2, one switch",
            "big": "big-station, station 1, two switches"}[result.kind]
    answered = len(lat)
    rows: list[Row] = [
        (f"N1MM flood {result.rate}/s: {name}",
         (f"{result.sent} packets in {result.wall:.1f} s; {answered} answered on the wire, "
         f"{result.sent - answered} not (kernel dropped {result.udp_drops})"),
         "all answered", _verdict(answered == result.sent)),
    ]
    if not lat:
        return rows
    rows.append(("  packet sent -> first byte at the switch",
                 (f"median {statistics.median(lat):.2f} ms, p90 {pct(lat, 90):.2f} ms, "
                 f"p99 {pct(lat, 99):.2f} ms, max {max(lat):.2f} ms"), "p99 < 5 ms",
                 _verdict(pct(lat, 99) < 5.0)))
    p99s = [p99 for _, _, _, p99 in result.per_second]
    counts = [n for _, n, _, _ in result.per_second]
    rows.append(("  each second: packets answered", " ".join(str(n) for n in counts), "flat",
                 _verdict(min(counts) >= 0.99 * result.rate)))
    rows.append(("  each second: p99 (ms)", " ".join(f"{p:.1f}" for p in p99s), "flat",
                 _verdict(max(p99s) < 5.0)))
    rows.append(("  kernel UDP receive queue, largest", f"{result.udp_queue_max} bytes", "", ""))
    cpu, wall = result.cpu, result.wall
    others = max(0.0, cpu["machine"] - cpu["server"] - cpu["emulators"] - cpu["sender"])
    rows.append(("  CPU, % of one core",
                 (f"server {100 * cpu['server'] / wall:.0f}, emulators {100 * cpu['emulators'] / wall:.0f},"
                 f" sender {100 * cpu['sender'] / wall:.0f}, other programs {100 * others / wall:.0f}"
                 f" (of {100 * (os.cpu_count() or 1)})"), "", ""))
    rows.append(("  server CPU per packet",
                 f"{1000 * cpu['server'] / max(1, result.sent):.2f} ms", "", ""))
    rows.append(("  server RSS before / after",
                 f"{result.rss_before_kb / 1024:.0f} MB / {result.rss_after_kb / 1024:.0f} MB",
                 "< 150 MB", _verdict(result.rss_after_kb / 1024 < 150)))
    rows.append(("  bytes on the wire per band change",
                 ", ".join(f"switch {s}: {b:.1f}" for s, b in sorted(result.bytes_per_change.items())),
                 "", ""))
    return rows


# --------------------------------------------------------------------------- (c)


def bytes_rows() -> list[Row]:
    """Bytes the link writes for band changes on the big station (its planner's count)."""
    from moas_gui.engine import Engine
    from moas_gui.engine.config import load_config
    from moas_gui.hw.moas2.sync import count_bytes

    engine = Engine(load_config(BIG).unwrap())
    rows = []
    start = {(1, 1): 14025.0, (2, 1): 21025.0}
    for (station, radio), khz in start.items():
        engine.set_frequency(station, radio, khz)
    moves = [((1, 1), 14025.0, 7025.0), ((1, 1), 7025.0, 3525.0), ((1, 1), 3525.0, 1825.0),
             ((2, 1), 21025.0, 28025.0), ((2, 1), 28025.0, 14225.0)]
    for (station, radio), before_khz, after_khz in moves:
        before = engine.switch_states()
        after = {**before, **engine.set_frequency(station, radio, after_khz).switches}
        counts = [f"switch {sid}: {count_bytes(before[sid], after[sid])}" for sid in sorted(before)]
        rows.append((f"bytes, big-station {station}/{radio} {_band(before_khz)} -> {_band(after_khz)}",
                     ", ".join(counts), "", ""))
    return rows


def _band(khz: float) -> str:
    for low, name in ((28000, "10 m"), (21000, "15 m"), (14000, "20 m"), (7000, "40 m"),
                      (3500, "80 m"), (1800, "160 m")):
        if khz >= low:
            return name
    return f"{khz:.0f} kHz"


# --------------------------------------------------------------------------- (d)


def cost_rows(kind: str, changes: int = 3000) -> list[Row]:
    """Where the server's time per band change goes, each part timed alone in this process."""
    from moas_gui.engine import Engine
    from moas_gui.engine.config import load_config
    from moas_gui.hw.moas2.sync import difference
    from moas_gui.net.n1mm_packet import parse_radio_info, radio_info_packet

    cycles = BANDS[kind]
    radios = sorted(cycles)
    steps = flood_packets([(ref[1], cycles[ref]) for ref in radios], changes)
    packets = [radio_info_packet(radio, khz) for radio, khz in steps]
    started = time.perf_counter()
    for packet in packets:
        parse_radio_info(packet)
    parse = time.perf_counter() - started

    engine = Engine(load_config(CONFIGS[kind]).unwrap())
    states = engine.switch_states()
    decided = []
    started = time.perf_counter()
    for number, (radio, khz) in enumerate(steps):
        decided.append(engine.set_frequency(1, radio, khz, now=number / 1000).switches)
    decide = time.perf_counter() - started
    started = time.perf_counter()
    for switches in decided:
        for switch_id, state in switches.items():
            difference(states[switch_id], state).encode()
            states[switch_id] = state
    plan = time.perf_counter() - started

    def each(seconds: float) -> str:
        return f"{1e6 * seconds / changes:.0f} us"

    return [(f"server work per band change ({kind}), alone",
             (f"parse RadioInfo {each(parse)}, engine decision {each(decide)}, "
             f"switch plan + bytes {each(plan)}"), "", "")]


# --------------------------------------------------------------------------- main


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
    with tempfile.TemporaryDirectory(prefix="bench-server-") as folder:
        work = Path(folder)
        (work / "settings").mkdir()
        if args.runs:
            rows += await bench_start(args.runs, not args.no_window, work)
        kinds = ["small", "big"] if args.flood == "both" else [args.flood]
        for kind in kinds:
            for rate in args.rate:
                rows += flood_rows(await bench_flood(kind, rate, args.seconds, work))
    for kind in kinds:
        rows += cost_rows(kind)
    rows += bytes_rows()
    print_table(rows)
    print(f"Load average after: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")


def main() -> int:
    if len(sys.argv) > 1 and sys.argv[1] == "--serve":
        return serve_child(sys.argv[2:])
    if len(sys.argv) > 1 and sys.argv[1] == "--send":
        send(int(sys.argv[2]), sys.argv[3])
        return 0
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3,
                        help="start-ups of each kind (default 3; 0 skips them)")
    parser.add_argument("--rate", type=lambda text: [int(x) for x in text.split(",")],
                        default=[1000], help="N1MM packets a second; several: 250,500,1000")
    parser.add_argument("--seconds", type=float, default=10.0, help="length of the flood")
    parser.add_argument("--flood", choices=("small", "big", "both"), default="both")
    parser.add_argument("--no-window", action="store_true", help="skip the window start-up")
    asyncio.run(run(parser.parse_args()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
