"""How long after a heading changes at the controller does the server's
rotator manager call back?  Target: within one poll interval + 50 ms.

Run: ``.venv/bin/python benchmarks/bench_rotators_server.py [--rounds N]``

- Serial: the fake MOAS Rotator program reports a changed heading (the
  program reports changes as it notices them, so the poll interval is the
  program's business; here it is the link's own delay that is measured).
- RotatorGenius: the emulator's rotor is moved; the manager polls ``|h``.
- Hamlib: a second manager's rotctld listener serves an Electrical rotator
  whose direction is changed; the first manager polls it with ``+p``.
Everything runs on 127.0.0.1 in one process.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import random
import socket
import statistics
import time
from collections.abc import Awaitable, Callable

from moas_gui.config.model import Rotator, RotatorControl
from moas_gui.hw.rotators import RotatorManager
from moas_gui.hw.rotators.base import RotatorView
from moas_gui.net.rotctld_server import start_rotctld_servers
from moas_gui.testing.fake_moas_rotator import FakeMoasRotator
from moas_gui.testing.genius_server import GeniusModel, GeniusServer


class Waiter:
    def __init__(self) -> None:
        self.wanted: tuple[int, int] | None = None
        self.future: asyncio.Future[float] | None = None

    def expect(self, rotator_id: int, heading: int) -> asyncio.Future[float]:
        self.wanted = (rotator_id, heading)
        self.future = asyncio.get_running_loop().create_future()
        return self.future

    def __call__(self, view: RotatorView) -> None:
        if self.future is not None and not self.future.done() \
                and (view.id, view.heading) == self.wanted:
            self.future.set_result(time.perf_counter())


async def measure(rounds: int, change: Callable[[int], Awaitable[None] | None],
                  waiter: Waiter, rotator_id: int, spread: float) -> list[float]:
    """Latencies in ms; ``spread`` s of random wait between changes so they fall
    anywhere in the poll cycle."""
    results = []
    for i in range(rounds):
        heading = 10 + (i * 37) % 340
        future = waiter.expect(rotator_id, heading)
        await asyncio.sleep(random.uniform(0, spread))
        began = time.perf_counter()
        maybe = change(heading)
        if maybe is not None:
            await maybe
        ended = await asyncio.wait_for(future, 10)
        results.append((ended - began) * 1000)
    return results


def report(name: str, poll_ms: float, latencies: list[float]) -> None:
    target = poll_ms + 50
    worst = max(latencies)
    verdict = "within target" if worst <= target else "OVER TARGET"
    print(f"{name:<34} poll {poll_ms:6.0f} ms  n={len(latencies):3d}  "
          f"median {statistics.median(latencies):7.1f} ms  "
          f"p95 {sorted(latencies)[int(0.95 * (len(latencies) - 1))]:7.1f} ms  "
          f"max {worst:7.1f} ms  target {target:6.0f} ms  {verdict}")


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


async def bench_serial(rounds: int) -> None:
    fake = FakeMoasRotator()
    await fake.start()
    waiter = Waiter()
    rotator = Rotator(id=1, control=RotatorControl.SERIAL, model="Yaesu", comm_port="COM1",
                      poll=1000)
    manager = RotatorManager([rotator], on_change=waiter, moas_rotator_port=fake.port,
                             start_moas_rotator=False)
    await manager.start()
    await asyncio.wait_for(fake.wait_for(lambda: 1 in fake.configured), 5)
    await asyncio.sleep(0.1)
    latencies = await measure(rounds, lambda h: fake.move_to("COM1", h), waiter, 1, 0.05)
    report("Serial (MOAS Rotator report)", 1000, latencies)
    await manager.close()
    await fake.close()


async def bench_genius(rounds: int, poll_ms: int) -> None:
    server = GeniusServer(GeniusModel())
    await server.start()
    waiter = Waiter()
    rotator = Rotator(id=2, control=RotatorControl.ROTATOR_GENIUS,
                      address=f"127.0.0.1:{server.port}", port=1, poll=poll_ms)
    manager = RotatorManager([rotator], on_change=waiter)
    await manager.start()
    await asyncio.sleep(0.3)
    latencies = await measure(
        rounds, lambda h: server.model.set_azimuth(1, h, server.now()), waiter, 2, poll_ms / 1000
    )
    report("RotatorGenius (|h poll)", poll_ms, latencies)
    await manager.close()
    await server.close()


async def bench_hamlib(rounds: int, poll_ms: int) -> None:
    port = free_port()
    source = RotatorManager([Rotator(id=3, control=RotatorControl.ELECTRICAL,
                                     rotctld_port=port)])
    await source.start()
    listeners = await start_rotctld_servers(source, [source.rotator(3)], "127.0.0.1")
    source.note_direction(3, 0)
    waiter = Waiter()
    client = RotatorManager([Rotator(id=4, control=RotatorControl.HAMLIB,
                                     address=f"127.0.0.1:{port}", poll=poll_ms)],
                            on_change=waiter)
    await client.start()
    await asyncio.sleep(0.3)
    latencies = await measure(rounds, lambda h: source.note_direction(3, h), waiter, 4,
                              poll_ms / 1000)
    report("Hamlib (+p poll of rotctld)", poll_ms, latencies)
    await client.close()
    for listener in listeners:
        await listener.close()
    await source.close()


async def main(rounds: int) -> None:
    print("time from a heading change at the peer to the manager's callback")
    await bench_serial(rounds)
    for poll in (250, 1000):
        await bench_genius(max(rounds // (4 if poll == 1000 else 1), 5), poll)
    for poll in (250, 1000):
        await bench_hamlib(max(rounds // (4 if poll == 1000 else 1), 5), poll)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=20)
    logging.basicConfig(level=logging.ERROR)
    asyncio.run(main(parser.parse_args().rounds))
