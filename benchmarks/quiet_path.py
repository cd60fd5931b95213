"""Where a logger packet's time goes on its way to the switch, for bench_server.py.

Two measures, both printed by ``bench_server.py`` in the same run as the floods:

* **The stages** (``--trace``): the server child stamps the monotonic clock at
  each stage of the path -- the datagram read, the RadioInfo parsed, the engine
  asked and answering, the switch port's write called and returned -- and
  writes the stamps to a file when it ends.  Nothing else changes in the
  server: the stamps are wrappers around the same calls.  For each packet of
  a quiet flood (each packet alone in its loop turn) the stamps after its
  ``sendto`` are lined up with its first byte at the switch.
* **The machine's floor**: the same hops with no work between them -- a
  sender process's UDP packet into an asyncio process, which writes a
  command to a pseudo-terminal through the program's serial layer, read by
  the event loop of this process -- at the same rates.  What the server adds
  is its latency minus the floor.
"""

from __future__ import annotations

import asyncio
import atexit
import functools
import gc
import json
import os
import pty
import signal
import socket
import statistics
import subprocess
import sys
import time
import tty
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

TRACE_ENV = "BENCH_SERVER_TRACE"
"""The file the server child writes its stamps to (set: stamp; unset: nothing changes)."""
COSTS_ENV = "BENCH_SERVER_COSTS"
"""The file the server child writes the CPU of each kind of loop callback to (``--costs``)."""
PROFILE_ENV = "BENCH_SERVER_PROFILE"
"""The file the server child writes its profile of a flood to (``--profile``): SIGUSR1
starts the profiler on the event loop's thread, SIGUSR2 stops it and writes the file."""

STAGES = ("received", "parsed", "decide", "decided", "write", "written", "turned", "saving")


# --------------------------------------------------------------------------- in the server


def install_stamps(path: str) -> None:
    """In the server child: stamp each stage of the path; write them to ``path`` at exit."""
    from moas_gui import app
    from moas_gui.serial.port import SerialPort
    from moas_gui.sources.n1mm import N1MMListener
    from moas_gui.sources.udp import DatagramSource

    stamps: dict[str, list[int]] = {name: [] for name in STAGES}
    clock = time.monotonic_ns

    def before(name: str, call: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(call)
        def stamped(*args: Any, **kwargs: Any) -> Any:
            stamps[name].append(clock())
            return call(*args, **kwargs)
        return stamped

    def around(first: str, then: str, call: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(call)
        def stamped(*args: Any, **kwargs: Any) -> Any:
            stamps[first].append(clock())
            try:
                return call(*args, **kwargs)
            finally:
                stamps[then].append(clock())
        return stamped

    def after(name: str, call: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(call)
        def stamped(*args: Any, **kwargs: Any) -> Any:
            try:
                return call(*args, **kwargs)
            finally:
                stamps[name].append(clock())
        return stamped

    DatagramSource.datagram_received = before(  # type: ignore[method-assign]
        "received", DatagramSource.datagram_received)
    N1MMListener.handle = after("parsed", N1MMListener.handle)  # type: ignore[method-assign]
    app.perform = around("decide", "decided", app.perform)  # type: ignore[attr-defined]
    SerialPort.write = around("write", "written", SerialPort.write)  # type: ignore[method-assign]
    # the end of the loop turn that decided, and the saved state's writes (each optional:
    # a renamed class leaves its stamp out, the rest still counts)
    from moas_gui import source_intake, state_store

    focus = getattr(source_intake, "SourceIntake", None)
    if focus is not None and hasattr(focus, "_decide"):
        focus._decide = after("turned", focus._decide)
    keeper = getattr(state_store, "StateKeeper", None)
    if keeper is not None and hasattr(keeper, "_start"):
        keeper._start = before("saving", keeper._start)

    collections: list[tuple[int, int, int]] = []
    """(generation, start, end) of each cyclic garbage collection."""
    began = [0]

    def collected(phase: str, info: dict[str, int]) -> None:
        if phase == "start":
            began[0] = clock()
        else:
            collections.append((info["generation"], began[0], clock()))

    gc.callbacks.append(collected)

    def dump() -> None:
        Path(path).write_text(json.dumps({**stamps, "gc": collections}))

    atexit.register(dump)


def install_costs(path: str) -> None:
    """In the server child: the event loop thread's CPU time (``time.thread_time_ns``)
    of each callback the loop runs, summed by what it calls, between SIGUSR1 and SIGUSR2
    (written to ``path`` as JSON).  About a microsecond of overhead a callback."""
    import signal

    clock = time.thread_time_ns
    costs: dict[str, list[int]] = {}
    on = [False]
    original = asyncio.events.Handle._run

    def name_of(handle: asyncio.Handle) -> str:
        callback = handle._callback  # type: ignore[attr-defined]
        owner = getattr(callback, "__self__", None)
        if isinstance(owner, asyncio.Task):
            coro = owner.get_coro()
            return f"task {getattr(coro, '__qualname__', coro)}"
        inner = getattr(callback, "func", callback)  # functools.partial
        return str(getattr(inner, "__qualname__", None) or type(inner).__name__)

    def measured(handle: asyncio.Handle) -> None:
        if not on[0]:
            original(handle)
            return
        began = clock()
        try:
            original(handle)
        finally:
            spent = clock() - began
            entry = costs.setdefault(name_of(handle), [0, 0])
            entry[0] += 1
            entry[1] += spent

    asyncio.events.Handle._run = measured  # type: ignore[method-assign,assignment]
    _measure_parts(costs, on, clock)
    loop_cpu = [0]

    def start(signum: int, frame: object) -> None:
        costs.clear()
        loop_cpu[0] = clock()
        on[0] = True

    def finish(signum: int, frame: object) -> None:
        on[0] = False
        costs["(the loop thread, all of it)"] = [0, clock() - loop_cpu[0]]
        Path(path).write_text(json.dumps(costs))

    signal.signal(signal.SIGUSR1, start)
    signal.signal(signal.SIGUSR2, finish)


PARTS = (
    ("moas_gui.sources.n1mm", "N1MMListener", "handle", "N1MM: the datagram taken"),
    ("moas_gui.sources.n1mm", None, "parse_radio_info", "N1MM: RadioInfo parsed"),
    ("moas_gui.source_intake", "SourceIntake", "set_focus", "intake: transmit/receive focus"),
    ("moas_gui.app", None, "perform", "app: engine decision (perform)"),
    ("moas_gui.app", "ServerApp", "apply_changes", "app: the decision sent out"),
    ("moas_gui.hw.moas2.link", "SwitchLink", "apply", "link: apply (plan, guard, write)"),
    ("moas_gui.serial.port", "SerialPort", "write", "serial: the write"),
    ("moas_gui.source_intake", "SourceIntake", "radio_entry", "intake: a radio entry for clients"),
    ("logging", "Logger", "handle", "logging: records shown"),
    ("moas_gui.state_store", "StateKeeper", "changed", "saved state: changed()"),
)
"""Parts timed inside the callbacks (``--costs``): module, class (None: a function of
the module, replaced where the path calls it), attribute, what the table calls it."""


def _measure_parts(costs: dict[str, list[int]], on: list[bool],
                   clock: Callable[[], int]) -> None:
    """Wrap each of :data:`PARTS` (those that exist) to add its thread CPU to ``costs``
    under ``"part: NAME"``; an inner part's time counts in its outer part too."""
    import importlib

    def wrapped(call: Callable[..., Any], label: str) -> Callable[..., Any]:
        @functools.wraps(call)
        def timed(*args: Any, **kwargs: Any) -> Any:
            if not on[0]:
                return call(*args, **kwargs)
            began = clock()
            try:
                return call(*args, **kwargs)
            finally:
                entry = costs.setdefault(f"part: {label}", [0, 0])
                entry[0] += 1
                entry[1] += clock() - began
        return timed

    for module_name, class_name, attribute, label in PARTS:
        try:
            module = importlib.import_module(module_name)
        except ImportError:
            continue
        owner = module if class_name is None else getattr(module, class_name, None)
        call = getattr(owner, attribute, None) if owner is not None else None
        if call is not None:
            setattr(owner, attribute, wrapped(call, label))


def costs_rows(path: Path, changes: int, rate: int, threads: dict[str, float],
               per: str = "") -> list[tuple[str, str, str, str]]:
    """The loop thread's CPU per band change by callback, and each thread's CPU (``per``:
    per what else, e.g. "second" for an idle server, ``changes`` then its seconds)."""
    costs: dict[str, list[int]] = json.loads(path.read_text())
    whole = costs.pop("(the loop thread, all of it)", [0, 0])[1]
    parts = {name.removeprefix("part: "): value for name, value in costs.items()
             if name.startswith("part: ")}
    costs = {name: value for name, value in costs.items() if not name.startswith("part: ")}
    counted = sum(ns for _, ns in costs.values())
    rows = [((f"  CPU per {per}" if per else f"  CPU per band change at {rate}/s")
             + ", by thread and by loop callback",
             f"us (calls per {per or 'change'})", "", "")]
    for name, seconds in sorted(threads.items(), key=lambda item: -item[1]):
        rows.append((f"    thread {name}", f"{1e6 * seconds / changes:.0f} us", "", ""))
    rows.append(("    the loop thread: callbacks", f"{counted / 1000 / changes:.0f} us", "", ""))
    rows.append(("    the loop thread: the loop itself (select, timers, signals)",
                 f"{(whole - counted) / 1000 / changes:.0f} us", "", ""))
    for name, (calls, ns) in sorted(costs.items(), key=lambda item: -item[1][1])[:15]:
        rows.append((f"      {name}", f"{ns / 1000 / changes:.0f} us ({calls / changes:.1f})",
                     "", ""))
    rows.append(("    parts inside the callbacks (an inner part counts in its outer too)", "",
                 "", ""))
    for name, (calls, ns) in sorted(parts.items(), key=lambda item: -item[1][1]):
        rows.append((f"      {name}", f"{ns / 1000 / changes:.0f} us ({calls / changes:.1f})",
                     "", ""))
    return rows


def cpu_clock(pid: int) -> float | None:
    """CPU seconds of process ``pid`` so far, to the nanosecond: Linux's CPU-time clock
    of another process (the id ``clock_getcpuclockid`` gives, made by hand: Python has
    no call for it); None where the system has no such clock or the process is gone.
    ``/proc``'s figures count in 10 ms ticks: at 10 band changes a second for 10 s, one
    tick is 5 % of a quiet flood's figure.  (A thread's clock may only be read from its
    own process: :func:`thread_cpu` counts ticks.)"""
    clock = ((~pid) << 3) | 2  # CPUCLOCK_SCHED of the whole process
    try:
        return time.clock_gettime_ns(clock) / 1e9
    except (OSError, OverflowError):
        return None


def thread_cpu(pid: int) -> dict[str, float]:
    """CPU seconds of each thread of ``pid`` so far, by thread id and name (``/proc``'s
    ticks: 10 ms)."""
    found: dict[str, float] = {}
    tick = os.sysconf("SC_CLK_TCK")
    try:
        tasks = list(Path(f"/proc/{pid}/task").iterdir())
    except OSError:
        return found
    for task in tasks:
        try:
            head, _, rest = (task / "stat").read_text().rpartition(")")
        except OSError:
            continue
        fields = rest.split()
        name = "loop" if task.name == str(pid) else head.partition("(")[2]
        found[f"{task.name} {name}"] = (int(fields[11]) + int(fields[12])) / tick
    return found


def install_profiler(path: str) -> None:
    """In the server child: SIGUSR1 starts profiling the event loop's thread, SIGUSR2
    stops and writes ``path`` (pstats).  The save's worker thread is not profiled: its
    CPU shows in the flood's figure, its calls not here."""
    import cProfile
    import signal

    profiler = cProfile.Profile()

    def start(signum: int, frame: object) -> None:
        profiler.enable()

    def finish(signum: int, frame: object) -> None:
        profiler.disable()
        profiler.dump_stats(path)

    signal.signal(signal.SIGUSR1, start)
    signal.signal(signal.SIGUSR2, finish)


IDLE = ("<method 'poll' of 'select.epoll' objects>", "<method 'select' of 'select.epoll' objects>")
"""The event loop waiting: time the profiler sees that is no work."""


def profile_rows(path: Path, changes: int, rate: int,
                 top: int = 25) -> list[tuple[str, str, str, str]]:
    """The functions that cost most (own time, the loop's wait left out) per band change
    of a quiet flood, and the cumulative time of the path's main steps."""
    import pstats

    stats = pstats.Stats(str(path))
    table: dict[Any, Any] = stats.stats  # type: ignore[attr-defined]
    busy = {key: value for key, value in table.items() if key[2] not in IDLE}
    total = sum(own for _, _, own, _, _ in busy.values())
    rows = [((f"  profile at {rate}/s (event loop's thread, per band change: busy "
             f"{1e3 * total / max(1, changes):.2f} ms with the profiler's overhead)"),
             "own us, with callees us, calls, share of busy", "", "")]
    ordered = sorted(busy.items(), key=lambda item: -item[1][2])
    for key, (_, calls, own, cumulative, _) in ordered[:top]:
        rows.append((f"    {_where(key)}",
                     (f"{1e6 * own / changes:.0f} us, {1e6 * cumulative / changes:.0f} us, "
                      f"{calls / changes:.1f}, {100 * own / max(total, 1e-9):.0f} %"), "", ""))
    return rows


def _where(key: tuple[str, int, str]) -> str:
    filename, line, function = key
    if filename == "~":
        return function
    return f"{function} ({Path(filename).parent.name}/{Path(filename).name}:{line})"


# --------------------------------------------------------------------------- in the bench


def _first_at_or_after(values: Sequence[int], moment: int, start: int = 0) -> tuple[int, int]:
    """(index, value) of the first of the sorted ``values`` at or after ``moment``."""
    for index in range(start, len(values)):
        if values[index] >= moment:
            return index, values[index]
    return -1, -1


def stage_rows(path: Path, sent: Sequence[int], latencies: dict[int, float],
               rate: int) -> list[tuple[str, str, str, str]]:
    """The median and p99 of each stage, over the packets that were alone in their turn."""
    stamps: dict[str, Any] = json.loads(path.read_text())
    spans: dict[str, list[float]] = {name: [] for name in (
        "sendto -> the server reads the datagram", "parse RadioInfo",
        "to the decision (the burst's end)", "engine decision",
        "switch plan -> write called", "the write itself", "write called -> first byte read")}
    names = list(spans)
    for seq, latency in sorted(latencies.items()):
        start = sent[seq]
        arrival = start + int(latency * 1e6)
        _, received = _first_at_or_after(stamps["received"], start)
        _, parsed = _first_at_or_after(stamps["parsed"], received)
        _, decide = _first_at_or_after(stamps["decide"], parsed)
        _, decided = _first_at_or_after(stamps["decided"], decide)
        write_index, write = _first_at_or_after(stamps["write"], decided)
        if min(received, parsed, decide, decided, write) < 0 or write > arrival:
            continue  # merged with another packet's turn, or stamps missing
        written = stamps["written"][write_index]
        for name, span in zip(names, (received - start, parsed - received, decide - parsed,
                                      decided - decide, write - decided, written - write,
                                      arrival - write), strict=True):
            spans[name].append(span / 1000)
    after_write: list[float] = []
    """Microseconds the server's turn went on after the packet's first write."""
    saves = 0
    """Packets whose first byte waited while the saved state was being collected."""
    for seq, latency in sorted(latencies.items()):
        start = sent[seq]
        arrival = start + int(latency * 1e6)
        _, write = _first_at_or_after(stamps["write"], start)
        _, turned = _first_at_or_after(stamps.get("turned", []), write)
        if 0 <= write <= arrival and turned >= 0:
            after_write.append((turned - write) / 1000)
            _, saving = _first_at_or_after(stamps.get("saving", []), write)
            saves += 0 <= saving <= arrival
    counted = len(spans[names[0]])
    first, last = sent[0], sent[-1]
    during = [(gen, (end - start) / 1e6) for gen, start, end in stamps.get("gc", [])
              if first <= start <= last]
    rows = [(f"  where the time goes at {rate}/s ({counted} packets alone in their turn)",
             "median / p99 in microseconds", "", "")]
    for name, values in spans.items():
        if values:
            rows.append((f"    {name}", (f"{statistics.median(values):.0f} / "
                                             f"{_pct(values, 99):.0f} us"), "", ""))
    if after_write:
        rows.append(("    the server's turn after the first write",
                     (f"{statistics.median(after_write):.0f} / {_pct(after_write, 99):.0f} us; "
                      f"the saved state started before the first byte arrived for {saves} "
                      f"of {len(after_write)} packets"), "", ""))
    by_generation = [sum(1 for gen, _ in during if gen == g) for g in range(3)]
    longest = max((ms for _, ms in during), default=0.0)
    rows.append(("    cyclic garbage collections during the flood",
                 (f"{len(during)} (generation 0/1/2: {'/'.join(map(str, by_generation))}), "
                  f"longest {longest:.2f} ms"), "", ""))
    return rows


def _pct(values: Sequence[float], p: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(p / 100 * len(ordered)))]


# --------------------------------------------------------------------------- the floor


def relay(slave: str) -> None:
    """The floor's middle process: each UDP datagram becomes a write to ``slave``."""
    from moas_gui.serial import PortSettings
    from moas_gui.serial.port import SerialPort

    async def main() -> None:
        loop = asyncio.get_running_loop()
        port = SerialPort(slave, PortSettings(exclusive=False))
        port.open(lambda data: None, lambda why: None)
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.bind(("127.0.0.1", 0))
        sock.setblocking(False)

        def readable() -> None:
            try:
                data = sock.recv(4096)
            except BlockingIOError:
                return
            port.write(b"!" + data + b";")

        loop.add_reader(sock.fileno(), readable)
        print(sock.getsockname()[1], flush=True)
        await loop.run_in_executor(None, sys.stdin.read)  # until the bench closes stdin

    asyncio.run(main())


def bare(config_path: str, mark: str) -> None:
    """The bare path: the floor's middle process with the parts of a band change between its
    hops -- each datagram parsed (RadioInfo), decided (the engine) and planned (the switch's
    fewest commands), the bytes written to the switch's terminal -- and nothing else: no
    log, no clients, no saved state, no periodic work.  What any server built on these
    parts must spend, read beside the server's figures (``--bare``)."""
    from moas_gui.config import load_config
    from moas_gui.engine import Engine
    from moas_gui.hw.moas2.sync import difference, initialise
    from moas_gui.serial import PortSettings
    from moas_gui.serial.port import SerialPort
    from moas_gui.sources.n1mm_packet import parse_radio_info

    config = load_config(Path(config_path)).unwrap()
    engine = Engine(config)
    states = dict(engine.switch_states())

    async def main() -> None:
        loop = asyncio.get_running_loop()
        ports = {}
        for switch in config.switches:
            port = SerialPort(switch.port, PortSettings(exclusive=False))
            port.open(lambda data: None, lambda why: None)
            port.write(initialise(states[switch.id]).encode())
            ports[switch.id] = port
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.bind(("127.0.0.1", 0))
        sock.setblocking(False)
        began = loop.time()

        def readable() -> None:
            try:
                data = sock.recv(4096)
            except BlockingIOError:
                return
            info = parse_radio_info(data)
            changes = engine.set_frequency(1, info.radio_nr, info.khz or 0.0,
                                           now=1.0 + loop.time() - began)
            for switch_id, state in changes.switches.items():
                ports[switch_id].write(difference(states[switch_id], state).encode())
                states[switch_id] = state

        loop.add_reader(sock.fileno(), readable)
        print(f"N1MM Logger on UDP 127.0.0.1:{sock.getsockname()[1]}", file=sys.stderr,
              flush=True)
        print(f"{mark} opened {time.monotonic_ns()} bare path", flush=True)
        ended = loop.create_future()
        loop.add_signal_handler(signal.SIGTERM, ended.set_result, None)
        await ended

    asyncio.run(main())


async def floor(bench: Path, root: Path, rate: int, seconds: float) -> tuple[list[float], float]:
    """Milliseconds from each ``sendto`` to its byte read from the pseudo-terminal, and the
    middle process's CPU seconds per packet (the hops' own cost: a wake, a read, a write)."""
    master, slave = pty.openpty()
    tty.setraw(slave)
    os.set_blocking(master, False)
    loop = asyncio.get_running_loop()
    arrivals: dict[int, int] = {}
    pending = bytearray()

    def readable() -> None:
        try:
            data = os.read(master, 4096)
        except OSError:
            return
        now = time.monotonic_ns()
        pending.extend(data)
        *done, rest = bytes(pending).split(b";")
        pending[:] = rest
        for command in done:
            arrivals.setdefault(int(command.lstrip(b"!")), now)

    relay_process = await asyncio.create_subprocess_exec(
        sys.executable, str(bench), "--relay", os.ttyname(slave), stdin=subprocess.PIPE,
        stdout=subprocess.PIPE, cwd=str(root))
    try:
        assert relay_process.stdout is not None
        port = int((await relay_process.stdout.readline()).decode())
        loop.add_reader(master, readable)
        count = int(rate * seconds)
        before = cpu_clock(relay_process.pid) or 0.0
        sender = await asyncio.create_subprocess_exec(
            sys.executable, str(bench), "--floor-send", str(port), str(rate), str(count),
            stdout=subprocess.PIPE, cwd=str(root))
        stdout, _ = await sender.communicate()
        await asyncio.sleep(0.5)
        hops = ((cpu_clock(relay_process.pid) or 0.0) - before) / max(1, count)
        sent: list[int] = json.loads(stdout)
    finally:
        loop.remove_reader(master)
        if relay_process.stdin is not None:
            relay_process.stdin.close()
        try:
            await asyncio.wait_for(relay_process.wait(), 5)
        except TimeoutError:
            relay_process.kill()
            await relay_process.wait()
        os.close(master)
        os.close(slave)
    return [(arrivals[seq] - at) / 1e6 for seq, at in enumerate(sent) if seq in arrivals], hops


def send_numbers(port: int, rate: int, count: int) -> None:
    """The floor's sender: datagrams holding their own number, paced as the floods are."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sent = [0] * count
    start = time.monotonic() + 0.1
    for seq in range(count):
        delay = start + seq / rate - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        sent[seq] = time.monotonic_ns()
        sock.sendto(str(seq).encode(), ("127.0.0.1", port))
    sock.close()
    print(json.dumps(sent))


__all__ = ["COSTS_ENV", "PROFILE_ENV", "STAGES", "TRACE_ENV", "bare", "costs_rows", "cpu_clock", "floor",
           "install_costs", "install_profiler", "install_stamps", "profile_rows", "relay",
           "send_numbers", "stage_rows", "thread_cpu"]
