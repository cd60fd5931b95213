"""How fast the MOAS II switch code is, and how few bytes it writes.

Run:  .venv/bin/python benchmarks/bench_moas2.py [--megabytes N] [--applies N]

Prints:

* decode throughput of the streaming decoder on mixed traffic (pings,
  antenna and T/R events, status replies, errors, a little garbage), fed in
  64-byte reads as a serial port delivers them, and in one piece.
  Target: at least 1 MB/s.
* the time from ``SwitchLink.apply()`` to the first byte handed to the port,
  for band changes on a six-station switch (median and 99th percentile,
  microseconds).  Target: under 1 ms.
* bytes written on the wire for a band change on the big-station example
  (one radio from 20 m to 40 m), computed by :func:`count_bytes`, which any
  later benchmark can reuse: it is the length of what the link would write.
"""

from __future__ import annotations

import argparse
import asyncio
import random
import statistics
import time
from pathlib import Path

from moas_gui.engine.switchstate import StationAntennas, SwitchState
from moas_gui.hw.moas2.decoder import SwitchDecoder
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.link import LinkStatus, SwitchLink
from moas_gui.hw.moas2.sync import count_bytes
from moas_gui.hw.moas2.transport import EmulatorTransport

ROOT = Path(__file__).resolve().parent.parent

TRAFFIC = [
    b"!;", b"!;", b"!;", b".;", b"<1A;", b">1A;", b"<2p;", b">2q;", b"!1F1;", b"!1f1;",
    b"!2S5;", b"!3c9;", b"!4X;", b"(12;", b")3;", b'"BTRRRRR12}}}}12}}}}}}}}}};',
    b'"I1;', b"|000000003y0;", b":1001;", b"?A;", b"xx\r\n", b"\x00", b"=garbage;",
]


def mixed_traffic(size: int, seed: int = 1) -> bytes:
    rng = random.Random(seed)
    parts: list[bytes] = []
    total = 0
    while total < size:
        part = rng.choice(TRAFFIC)
        parts.append(part)
        total += len(part)
    return b"".join(parts)


def bench_decoder(megabytes: float) -> None:
    data = mixed_traffic(int(megabytes * 1_000_000))
    for label, chunk in (("64-byte reads", 64), ("one piece", len(data))):
        decoder = SwitchDecoder()
        start = time.perf_counter()
        count = 0
        for i in range(0, len(data), chunk):
            count += len(decoder.feed(data[i : i + chunk]))
        seconds = time.perf_counter() - start
        print(f"decoder, {label:13}: {len(data) / seconds / 1e6:6.2f} MB/s "
              f"({count} messages from {len(data) / 1e6:.1f} MB)  target >= 1 MB/s")


class StampingTransport(EmulatorTransport):
    """The in-process emulator, noting when the first byte of each write arrives."""

    def __init__(self, box: EmulatedBox) -> None:
        super().__init__(box)
        self.first_byte_at: float | None = None

    def write(self, data: bytes) -> None:
        if self.first_byte_at is None:
            self.first_byte_at = time.perf_counter()
        super().write(data)


def six_station_states() -> list[SwitchState]:
    """Band plans for a six-station switch: each station on its own band, rotating."""
    conflicts = frozenset((a, a) for a in range(36))
    fast = frozenset((a, b) for a in range(36) for b in range(a, 36) if a // 6 == b // 6)
    states = []
    for shift in range(6):
        stations = []
        for n in range(6):
            band = (n + shift) % 6
            slot = band * 6 + n
            relays = frozenset({band * 8 + n, 48 + n})
            stations.append(StationAntennas(tx=slot, tx_relays=relays, rx=slot, rx_relays=relays,
                                            extra=frozenset({56 + band})))
        states.append(SwitchState(stations=tuple(stations), conflicts=conflicts, fast=fast))
    return states


async def bench_apply(applies: int) -> None:
    box = EmulatedBox()
    transport = StampingTransport(box)
    link = SwitchLink(1, "bench", transport=transport)
    states = six_station_states()
    link.apply(states[0])
    link.connect()
    while link.status is not LinkStatus.OK:
        await asyncio.sleep(0.005)
    delays: list[float] = []
    one_station: list[float] = []
    for i in range(applies):
        base = states[i % len(states)]
        # Half the time one station changes band, half the time all six rotate.
        if i % 2:
            changed = list(base.stations)
            changed[i % 6] = states[(i + 1) % 6].stations[i % 6]
            state = SwitchState(stations=tuple(changed), conflicts=base.conflicts, fast=base.fast)
        else:
            state = base
        transport.first_byte_at = None
        start = time.perf_counter()
        link.apply(state)
        if transport.first_byte_at is not None:
            (one_station if i % 2 else delays).append(transport.first_byte_at - start)
        if i % 50 == 0:
            await asyncio.sleep(0)
    await link.close()
    for label, values in (("all six stations", delays), ("one station", one_station)):
        values.sort()
        p99 = values[int(len(values) * 0.99) - 1]
        print(f"apply() to first byte, {label:16}: median {statistics.median(values) * 1e6:6.1f} us,"
              f" p99 {p99 * 1e6:6.1f} us ({len(values)} applies)  target < 1000 us")


def bench_bytes_on_the_wire() -> None:
    states = six_station_states()
    print(f"bytes for one station changing band (six-station switch): "
          f"{count_bytes(states[0], _one_changed(states))}")
    print(f"bytes for all six stations changing band at once:        "
          f"{count_bytes(states[0], states[1])}")
    try:
        from moas_gui.config import load_config
        from moas_gui.engine import Engine
    except ImportError as exc:
        print(f"big-station band change: engine not available ({exc})")
        return
    result = load_config(ROOT / "examples" / "big-station.moas")
    if not result.ok:
        print("big-station band change: the example does not load")
        return
    engine = Engine(result.config)
    for view in engine.radios():
        engine.set_frequency(view.station, view.radio, 14025 + 10 * view.station)
    before = engine.switch_states()
    first = engine.radios()[0]
    after = {**before, **engine.set_frequency(first.station, first.radio, 7025).switches}
    for switch_id in sorted(before):
        print(f"big-station, station {first.station} radio {first.radio} from 20 m to 40 m, "
              f"switch {switch_id}: {count_bytes(before[switch_id], after[switch_id])} bytes")


def _one_changed(states: list[SwitchState]) -> SwitchState:
    stations = list(states[0].stations)
    stations[0] = states[1].stations[0]
    return SwitchState(stations=tuple(stations), conflicts=states[0].conflicts,
                       fast=states[0].fast)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--megabytes", type=float, default=4.0)
    parser.add_argument("--applies", type=int, default=4000)
    args = parser.parse_args()
    bench_decoder(args.megabytes)
    asyncio.run(bench_apply(args.applies))
    bench_bytes_on_the_wire()


if __name__ == "__main__":
    main()
