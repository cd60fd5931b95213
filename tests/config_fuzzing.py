"""Mutating configuration files and checking that the reader copes: shared by the fuzz
tests (a fixed, small corpus) and ``benchmarks/bench_config_fuzz.py`` (a large one).

A mutation is what a station's file meets: cut short (a crash, a full disk, a half
copy), bytes flipped, spans deleted or inserted, a value of one type where another
belongs.  Reading a mutated file must give a usable configuration or problems, each
at a line and column, and never an exception or a long wait.
"""

from __future__ import annotations

import json
import random
import re
import time
import traceback
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from moas_gui.engine.config import read_config

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"

BANDS = ((1800, 2000), (3500, 4000), (7000, 7300), (14000, 14350), (21000, 21450),
         (28000, 29700))


def station(seed: int, antennas: int = 12, stations: int = 2, radios: int = 2) -> str:
    """A complete, valid station (every kind of group) made from ``seed``."""
    rng = random.Random(seed)
    switches = 1 + (stations * radios * antennas) // 120
    refs = [(s, r) for s in range(1, stations + 1) for r in range(1, radios + 1)]
    relay_of: dict[tuple[int, int, int], int] = {}
    free = [switch * 100 + local for switch in range(switches) for local in range(64)]
    antenna_list = []
    for ident in range(1, antennas + 1):
        low, high = BANDS[rng.randrange(len(BANDS))]
        per_station = []
        for s, r in refs:
            relay = free.pop(rng.randrange(len(free))) if free else 0
            relay_of[(ident, s, r)] = relay
            per_station.append({"Station": s, "Radio": r, "Relays": [relay]})
        antenna_list.append({
            "ID": ident, "ShortName": f"A{ident}", "LongName": f"Antenna {ident}",
            "Conflicts": [ident], "Fast": rng.sample(range(1, antennas + 1), min(3, antennas)),
            "Rotator": 1 if ident % 3 == 0 else None,
            "Control": [{"LowerFrequency": low, "UpperFrequency": high,
                         "Stations": per_station}],
        })
    for antenna in antenna_list:
        if antenna["Rotator"] is None:
            del antenna["Rotator"]
    members = list(range(1, min(antennas, 4) + 1))
    config = {
        "Templates": [{"Name": "Yagi", "Type": "yagi", "Info": [
            {"LowerFrequency": 14000, "UpperFrequency": 14350, "Elements": 3,
             "3dBWidth": 70, "Lobes": 1}]}],
        "Antennas": antenna_list,
        "Systems": [{"ID": 1, "DisplayName": "Stack", "ExclusiveAntennas": members}],
        "Functions": [
            {"ID": 0, "Name": "AntennaSwap", "IntParams": [*refs[0], *refs[-1]]},
            {"ID": 1, "Name": "Store", "IntParams": [], "StringParams": []},
            {"ID": 2, "Name": "Relay", "IntParams": [free[0] if free else 63],
             "StringParams": ["T"]},
        ],
        "Layout": [{"Rows": 2 + antennas // 6, "Columns": 6, "Matrix": [{"Buttons": [
            {"Row": (i - 1) // 6, "Column": (i - 1) % 6, "Type": "Antenna", "ID": i}
            for i in range(1, antennas + 1)] + [
            {"Row": 1 + antennas // 6, "Column": 0, "Type": "Function", "ID": 0}]}]}],
        "RelativeAntennas": [{"Antennas": [{"IDs": members}]}],
        "Rotators": [{"ID": 1, "ShortName": "Tower", "Control": "Test", "HasStop": True,
                      "CCWLimit": 180, "Rotation": 360}],
        "Radios": [{"Station": s, "Radio": r,
                    "Always": [{"Station": s, "Radio": o} for o in range(1, radios + 1)
                               if o != r],
                    "Switches": [{"Switch": 1, "Port": index % 6 + 1}] if index < 6 else
                    [{"Switch": 1 + index // 6, "Port": index % 6 + 1}]}
                   for index, (s, r) in enumerate(refs)],
        "Switches": [{"ID": i, "Port": "emulator", "IndicateTR": rng.random() < 0.5}
                     for i in range(1, max(switches, 1 + (len(refs) - 1) // 6) + 1)],
        "TCPPort": 12059, "UDPPort": 12060, "UseN1MMLogger": True,
        "N1MMLogger": [{"Address": f"192.168.1.{20 + s}", "Station": s}
                       for s in range(1, stations + 1)],
        "ClientAllow": ["127.0.0.1", "192.168.1.0/24"],
        "ProtectSameBand": rng.random() < 0.5, "StartMOASRotator": False,
    }
    return json.dumps(config, indent=2 if seed % 2 else None)


def corpus(generated: int = 3) -> dict[str, bytes]:
    """Every example, and ``generated`` generated stations of growing size."""
    files = {p.name: p.read_bytes() for p in sorted(EXAMPLES.glob("*.moas"))}
    for seed in range(generated):
        files[f"generated-{seed}.moas"] = station(
            seed, antennas=8 + 20 * seed, stations=1 + seed % 3, radios=2).encode()
    return files


# -- mutations ------------------------------------------------------------------------
TOKENS = [b'"', b"{", b"}", b"[", b"]", b",", b":", b"0", b"-", b".", b"'", b"//", b"/*",
          b"\\", b"\n", b"true", b"True", b"null", b"NaN", b"1e999", b"01e999", b"-0",
          b"9" * 5000, b'"x"', b'"\\u12"', b"\xff", b"\xc3", b"\xe2\x82", b"\x00", b"\xef\xbb\xbf",
          b'"TCPPort":', b'{"ID": 1}', b"[[[[[[[[", b"]]]]]]", b"2147483648", b"1.5"]
"""Bytes a mutation may insert: punctuation, words, numbers of every oddity, broken UTF-8."""

OTHER_VALUES = [b'"1"', b'"x"', b"0", b"-1", b"1.5", b"1e999", b"-1e999", b"2147483648",
                b"9" * 400, b"true", b"false", b"null", b"[]", b"{}", b"[1]", b'{"ID": 1}',
                b'[""]', b'"emulator"', b"[1, 1, 1]", b"65536"]
"""Values a type swap may put where another value was."""

SCALAR = re.compile(rb'"(?:[^"\\\n]|\\.)*"|-?\d+(?:\.\d+)?(?:[eE][+-]?\d+)?|true|false|null')


def truncate(rng: random.Random, data: bytes) -> bytes:
    return data[: rng.randrange(len(data))]


def flip(rng: random.Random, data: bytes) -> bytes:
    out = bytearray(data)
    for _ in range(rng.choice((1, 1, 1, 2, 4))):
        at = rng.randrange(len(out))
        out[at] ^= 1 << rng.randrange(8)
    return bytes(out)


def delete(rng: random.Random, data: bytes) -> bytes:
    at = rng.randrange(len(data))
    return data[:at] + data[at + rng.choice((1, 1, 2, 5, 20, 200)):]


def insert(rng: random.Random, data: bytes) -> bytes:
    at = rng.randrange(len(data) + 1)
    if rng.random() < 0.3:  # a copy of a span elsewhere in the file
        start = rng.randrange(len(data))
        piece = data[start: start + rng.choice((1, 10, 100, 1000))]
    else:
        piece = rng.choice(TOKENS)
    return data[:at] + piece + data[at:]


def swap_type(rng: random.Random, data: bytes) -> bytes:
    """Replace one value (a number, text, true, false or null) with a value of another type."""
    for _ in range(8):
        at = rng.randrange(len(data))
        match = SCALAR.search(data, at)
        if match is None:
            continue
        others = [v for v in OTHER_VALUES if v != match.group()]
        return data[: match.start()] + rng.choice(others) + data[match.end():]
    return data


MUTATIONS: dict[str, Callable[[random.Random, bytes], bytes]] = {
    "truncation": truncate, "byte flip": flip, "deletion": delete, "insertion": insert,
    "type swap": swap_type,
}


# -- checking one file -------------------------------------------------------------------
@dataclass(frozen=True)
class Outcome:
    """What reading one mutated file gave."""

    problems: int
    seconds: float
    """Processor time the reading took (the reading thread's own, so a busy machine
    does not make a quick reading look slow)."""
    usable: bool
    crash: str | None = None
    unplaced: str | None = None


def read(data: bytes, name: str) -> Outcome:
    """Read ``data`` as a configuration; an exception is caught and described, not raised."""
    started = time.thread_time()
    try:
        result = read_config(data, name)
    except Exception:  # noqa: BLE001 - the point is to record any crash
        return Outcome(0, time.thread_time() - started, False,
                       crash=traceback.format_exc(limit=-3))
    seconds = time.thread_time() - started
    unplaced = next((str(p) for p in result.problems if p.line < 1 or p.column < 1), None)
    return Outcome(len(result.problems), seconds, result.ok, unplaced=unplaced)


def mutations(files: dict[str, bytes], count: int, seed: int
              ) -> Iterator[tuple[str, str, bytes]]:
    """``count`` mutated files, ``(file name, mutation kind, bytes)``, the same for a seed."""
    rng = random.Random(seed)
    names = sorted(files)
    kinds = sorted(MUTATIONS)
    for index in range(count):
        name = names[index % len(names)]
        kind = kinds[(index // len(names)) % len(kinds)]
        data = MUTATIONS[kind](rng, files[name])
        if data and rng.random() < 0.2:  # now and then a second mutation on top of the first
            data = MUTATIONS[rng.choice(kinds)](rng, data)
        yield name, kind, data


__all__ = ["MUTATIONS", "Outcome", "corpus", "mutations", "read", "station"]
