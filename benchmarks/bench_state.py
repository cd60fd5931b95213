"""What keeping the saved state costs (docs/server.md, "After a restart").

    .venv/bin/python benchmarks/bench_state.py [--example big-station.moas] [--rounds 200]

Prints, for the example with every radio tuned:

* collect + encode: the part of a save that runs on the event loop (the
  engine's selections and every switch's state to JSON bytes), at most once
  per ``SAVE_DELAY_S`` however many packets arrive;
* a burst of 10,000 changes: how many writes the keeper makes (coalescing);
* write: temporary file, fsync, rename, fsync of the directory (on a worker
  thread in the server), in a temporary directory of this file system;
* decode + restore: what a start adds, with a fresh engine made for it.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import tempfile
import time
from pathlib import Path

from moas_gui.config import load_config
from moas_gui.engine import Engine, EngineError
from moas_gui.engine.snapshot import export_selections, restore_selections
from moas_gui.state_store import SavedState, StateKeeper, decode, encode, write_atomic

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
BANDS = (1830.0, 3510.0, 7020.0, 14025.0, 21030.0, 28040.0)


def _tuned(path: Path) -> Engine:
    engine = Engine(load_config(path).unwrap())
    for view, khz in zip(engine.radios(), BANDS * 20, strict=False):
        with contextlib.suppress(EngineError):
            engine.set_frequency(view.station, view.radio, khz)
    return engine


def _per_call_ms(rounds: int, call: object) -> float:
    start = time.perf_counter()
    for _ in range(rounds):
        call()  # type: ignore[operator]
    return (time.perf_counter() - start) / rounds * 1000


async def _burst(directory: Path, saved: SavedState) -> int:
    keeper = StateKeeper(directory / "burst.json", lambda: saved, delay=0.05)
    for _ in range(10_000):
        keeper.changed()
    await asyncio.sleep(0.2)
    await keeper.flush()
    return keeper.writes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--example", default="big-station.moas")
    parser.add_argument("--rounds", type=int, default=200)
    args = parser.parse_args()
    path = EXAMPLES / args.example
    engine = _tuned(path)
    states = engine.switch_states()

    def collect() -> bytes:
        return encode(SavedState("0" * 64, export_selections(engine), states))

    data = collect()
    print(f"{args.example}: {len(engine.radios())} radios, {len(states)} switches, "
          f"state file {len(data)} bytes")
    print(f"collect + encode (on the loop):  {_per_call_ms(args.rounds, collect):7.3f} ms")
    config = engine.config

    def start() -> None:
        restore_selections(Engine(config), decode(data, "0" * 64).engine)

    print(f"decode + restore (at start):     {_per_call_ms(args.rounds, start):7.3f} ms")
    print(f"  of which a fresh engine:       {_per_call_ms(args.rounds, lambda: Engine(config)):7.3f} ms")
    with tempfile.TemporaryDirectory(dir=Path.cwd()) as directory:
        target = Path(directory) / "state.json"
        rounds = max(10, args.rounds // 4)
        ms = _per_call_ms(rounds, lambda: write_atomic(target, data))
        print(f"write (temporary, fsync, rename): {ms:7.3f} ms  (worker thread)")
        saved = SavedState("0" * 64, export_selections(engine), states)
        writes = asyncio.run(_burst(Path(directory), saved))
        print(f"10,000 changes in a burst:       {writes:7d} write(s)")


if __name__ == "__main__":
    main()
