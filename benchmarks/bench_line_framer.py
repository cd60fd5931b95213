"""The line framer every line protocol reads through: time per line.

Prints, for each line-end policy, the best of several runs (the machine's
noise only ever adds time) of:

- one request line per ``feed`` (a client's request as it usually arrives);
- a hundred lines per ``feed`` (a burst);
- one byte per ``feed`` (a serial port read byte by byte, OTRSP's worst case);

and the same for each protocol's decoder built on it (client protocol replies,
MOAS Rotator reports and commands, OTRSP), so a change to the framer that costs
a protocol time shows here.  No figure is a test: see tests/net/test_line_framer.py.

Run: ``.venv/bin/python benchmarks/bench_line_framer.py [--repeat 7]``
"""

from __future__ import annotations

import argparse
import timeit
from collections.abc import Callable

from moas_gui.client.codec import ClientCodec
from moas_gui.hw.rotators.moas_rotator_codec import CommandDecoder, ReportDecoder
from moas_gui.line_framer import LineEnd, LineFramer
from moas_gui.sources.otrsp_command import CommandParser

REQUEST = b'{"id":12,"cmd":"select","station":1,"radio":1,"antenna":3}\n'


def per_call(make: Callable[[], Callable[[bytes], object]], data: bytes, calls: int,
             repeat: int) -> float:
    """Best time of one call of ``feed(data)``, in microseconds."""
    feed = make()
    return min(timeit.repeat(lambda: feed(data), number=calls, repeat=repeat)) / calls * 1e6


def bytewise(make: Callable[[], Callable[[bytes], object]], data: bytes, repeat: int) -> float:
    """Best time to feed ``data`` one byte at a time, in microseconds per line."""
    pieces = [data[i:i + 1] for i in range(len(data))]

    def run() -> None:
        feed = make()
        for piece in pieces:
            feed(piece)

    return min(timeit.repeat(run, number=200, repeat=repeat)) / 200 * 1e6


def report(name: str, make: Callable[[], Callable[[bytes], object]], line: bytes,
           repeat: int) -> None:
    one = per_call(make, line, 20_000, repeat)
    burst = per_call(make, line * 100, 200, repeat) / 100
    slow = bytewise(make, line, repeat)
    print(f"{name:<34} {one:8.2f} {burst:10.2f} {slow:10.1f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="runs; the best is shown")
    repeat = parser.parse_args().repeat
    print(f"{'microseconds per line':<34} {'1/feed':>8} {'100/feed':>10} {'1 byte/feed':>10}")
    report("framer, LF (client protocol)", lambda: LineFramer(65_536, LineEnd.LF).feed,
           REQUEST, repeat)
    report("framer, CR or LF (MOAS Rotator)",
           lambda: LineFramer(512, LineEnd.CR_OR_LF).feed, b"ROTATE 1 270\r", repeat)
    report("client codec (reply line)", lambda: ClientCodec().feed,
           b'{"id":12,"ok":true,"result":{}}\n', repeat)
    report("MOAS Rotator reports", lambda: ReportDecoder().feed, b"1 270\r", repeat)
    report("MOAS Rotator commands", lambda: CommandDecoder().feed, b"ROTATE 1 270\r", repeat)
    report("OTRSP commands", lambda: CommandParser().feed, b"AUX13\r", repeat)


if __name__ == "__main__":
    main()
