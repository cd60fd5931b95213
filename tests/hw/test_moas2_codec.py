"""The MOAS II codec: sixbit, every command of the programming manual (its
examples, with the ERRATA fixes), the 40-byte limit and the splitting."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from moas_gui.hw.moas2.commands import (
    COMMANDS,
    MAX_COMMAND,
    MAX_PAIRS,
    MAX_RELAYS,
    command_name,
    encode,
    encode_all,
    parse_command,
    split,
)
from moas_gui.hw.moas2.errors import CommandRejected, CommandTooLong, EncodeError, RelayListTooLong
from moas_gui.hw.moas2.messages import (
    AntennaKind,
    ConflictOp,
    ConflictTable,
    FastOp,
    FastTable,
    Inhibit,
    InhibitOthers,
    InhibitPolarity,
    InhibitTime,
    InterruptDelay,
    Mode,
    Ping,
    PolarityOp,
    ReceiveDelay,
    RelayStatusRequest,
    SetAntenna,
    SetState,
    StateOp,
    StationMode,
    StatusKind,
    StatusRequest,
    SystemTable,
    Uninhibit,
    UnitId,
    UseAlternate,
    VendorExtension,
)
from moas_gui.hw.moas2.sixbit import (
    ALPHABET,
    SixbitError,
    decode_relay_bitmap,
    encode_relay_bitmap,
    from_char,
    to_char,
)

# --------------------------------------------------------------------------- sixbit


@pytest.mark.parametrize(
    ("number", "char"),
    [(0, "0"), (9, "9"), (10, "A"), (16, "G"), (35, "Z"), (36, "a"), (51, "p"), (61, "z"),
     (62, "{"), (63, "}")],
)
def test_sixbit_matches_the_manuals_table(number: int, char: str) -> None:
    assert to_char(number) == char
    assert from_char(char) == number


def test_sixbit_round_trips_every_number() -> None:
    assert [from_char(to_char(n)) for n in range(64)] == list(range(64))
    assert len(set(ALPHABET)) == 64


@pytest.mark.parametrize("bad", [-1, 64, 1000])
def test_sixbit_refuses_numbers_outside_0_to_63(bad: int) -> None:
    with pytest.raises(SixbitError, match=str(bad)):
        to_char(bad)


@pytest.mark.parametrize("bad", [";", "!", " ", "~", "é"])
def test_sixbit_refuses_characters_outside_the_alphabet(bad: str) -> None:
    with pytest.raises(SixbitError, match="not a sixbit"):
        from_char(bad)


def test_relay_map_examples_from_the_manual() -> None:
    assert decode_relay_bitmap("00000000007") == {0, 1, 2}
    # ERRATA: the manual lists "8, 9, 10, 10, 11, 12, 13"; it is relays 8-13.
    assert decode_relay_bitmap("000000003y0") == set(range(8, 14))
    assert encode_relay_bitmap({8, 9, 10, 11, 12, 13}) == "000000003y0"


@given(st.frozensets(st.integers(0, 63)))
def test_relay_map_round_trips_any_relays(relays: frozenset[int]) -> None:
    text = encode_relay_bitmap(relays)
    assert len(text) == 11
    assert decode_relay_bitmap(text) == relays


def test_relay_map_with_bits_beyond_relay_63_is_refused() -> None:
    with pytest.raises(SixbitError, match="beyond relay 63"):
        decode_relay_bitmap("G0000000000")


# --------------------------------------------------------------------------- the manual's examples

MANUAL_EXAMPLES = [
    ("!1B1123;", SetAntenna(1, AntennaKind.BOTH, 1, (1, 2, 3))),
    ("!4TAF;", SetAntenna(4, AntennaKind.TX, 10, (15,))),
    # ERRATA: the manual says "station 4"; it is station 2's extra relays 61 and 63.
    ("!2X0z};", SetAntenna(2, AntennaKind.EXTRA, 0, (61, 63))),
    ("%0;", ConflictTable(ConflictOp.NONE)),
    (
        "%C00112233445566778899AABBCCDDEEFF;",
        ConflictTable(ConflictOp.SET, tuple((n, n) for n in range(16))),
    ),
    ("&1;", FastTable(FastOp.ALL_FAST)),
    ("&f12;", FastTable(FastOp.SLOW, ((1, 2),))),
    ("(12;", Inhibit(frozenset({1, 2}))),
    ("~12;", InhibitOthers(1, frozenset({2}))),
    ("~21;", InhibitOthers(2, frozenset({1}))),
    ("^0;", InhibitPolarity(PolarityOp.ALL_INHIBIT_LOW)),
    ("^E1;", InhibitPolarity(PolarityOp.ENABLE_LOW, frozenset({1}))),
    ("[30;", InhibitTime(30)),
    ("]20;", InterruptDelay(20)),
    ("/I123456;", Mode(StationMode.INTERRUPT, frozenset(range(1, 7)))),
    # ERRATA: Ping is ';, not !;
    ("';", Ping()),
    ("\\1200;", ReceiveDelay(1, 200)),
    # ERRATA: Relay status is |;
    ("|;", RelayStatusRequest()),
    ("*ATI;", SetState((StateOp.ANTENNA_EVENTS_ON, StateOp.TR_EVENTS_ON,
                        StateOp.INHIBIT_EVENTS_ON))),
    ("*1;", SetState((StateOp.ACTIVATE,))),
    ('"B;', StatusRequest(StatusKind.BOX)),
    ('"I;', StatusRequest(StatusKind.POLARITY)),
    ("_0;", SystemTable(clear=True)),
    # ERRATA: Uninhibit is ), not (.
    (")12;", Uninhibit(frozenset({1, 2}))),
    (":1;", UnitId(1)),
    (":;", UnitId()),
    # ERRATA: Use Alternate ends with ; like every command.
    ("@12;", UseAlternate(1, frozenset({2}))),
]


@pytest.mark.parametrize(("text", "command"), MANUAL_EXAMPLES)
def test_manual_example_encodes_and_parses(text: str, command: object) -> None:
    assert encode(command) == text.encode()  # type: ignore[arg-type]
    assert parse_command(text[:-1]) == command


def test_system_example_without_sub_command_is_read_as_pairs() -> None:
    # The manual's own example "_112131;" has no "S": read as antennas 1-3 in system 1.
    assert parse_command("_112131") == SystemTable(False, ((1, 1), (2, 1), (3, 1)))
    assert parse_command("_S112131") == SystemTable(False, ((1, 1), (2, 1), (3, 1)))
    assert encode(SystemTable(False, ((1, 1), (2, 1), (3, 1)))) == b"_S112131;"


def test_every_command_of_the_manual_has_a_table_row() -> None:
    names = {rule.name for rule in COMMANDS.values()}
    assert names == {
        "Antenna", "Conflict table", "Fast table", "Inhibit", "Inhibit other station",
        "Inhibit polarity", "Inhibit time", "Interrupt mode delay", "Mode", "Ping",
        "Receive delay", "Relay status", "Set state", "Status", "System", "Uninhibit",
        "Unit ID", "Use alternate antenna", "Vendor extension",
    }
    assert command_name(Ping()) == "Ping"


# --------------------------------------------------------------------------- limits


def test_antenna_with_35_relays_is_exactly_40_bytes() -> None:
    command = SetAntenna(1, AntennaKind.BOTH, 5, tuple(range(MAX_RELAYS)))
    assert len(encode(command)) == MAX_COMMAND == 40


def test_antenna_with_36_relays_is_refused_naming_station_and_count() -> None:
    command = SetAntenna(3, AntennaKind.TX, 5, tuple(range(36)))
    with pytest.raises(RelayListTooLong, match=r"station 3 TX antenna 5 needs 36 relays"):
        encode(command)
    assert isinstance(RelayListTooLong("x"), CommandTooLong)


def test_long_table_loads_are_split_into_commands_of_at_most_40_bytes() -> None:
    pairs = tuple((a, b) for a in range(10) for b in range(a, 10))  # 55 pairs
    command = ConflictTable(ConflictOp.SET, pairs)
    parts = split(command)
    assert len(parts) == 4
    assert all(len(encode(p)) <= MAX_COMMAND for p in parts)
    assert sum((p.pairs for p in parts), ()) == pairs  # type: ignore[union-attr]
    assert max(len(p.pairs) for p in parts) == MAX_PAIRS  # type: ignore[union-attr]
    with pytest.raises(CommandTooLong):
        encode(command)
    assert encode_all([command]) == b"".join(encode(p) for p in parts)


@given(
    st.sampled_from([ConflictOp.SET, ConflictOp.CLEAR]),
    st.lists(st.tuples(st.integers(0, 63), st.integers(0, 63)), max_size=200),
)
def test_split_table_loads_never_exceed_40_bytes(op: ConflictOp, pairs: list) -> None:
    data = encode_all([ConflictTable(op, tuple(pairs))])
    commands = data.split(b";")[:-1]
    assert all(len(c) + 1 <= MAX_COMMAND for c in commands)
    parsed = [parse_command(c.decode()) for c in commands]
    assert sum((p.pairs for p in parsed), ()) == tuple(pairs)  # type: ignore[union-attr]


@pytest.mark.parametrize(
    ("command", "message"),
    [
        (SetAntenna(7, AntennaKind.TX, 1), "station 7"),
        (SetAntenna(0, AntennaKind.TX, 1), "station 0 takes only extra relays"),
        (SetAntenna(1, AntennaKind.TX, 64), "antenna 64"),
        (SetAntenna(1, AntennaKind.TX, 1, (64,)), "relay"),
        (InhibitTime(0), "inhibit time of 0 ms"),
        (InhibitTime(10000), "outside 1-9999"),
        (InterruptDelay(100), "interrupt delay of 100 ms"),
        (ReceiveDelay(1, 10000), "receive delay"),
        (UnitId(100), "unit identifier 100"),
        (InhibitOthers(1, frozenset({1})), "cannot inhibit itself"),
        (UseAlternate(2, frozenset({2})), "cannot move itself"),
        (SetState(()), "at least one sub-command"),
        (ConflictTable(ConflictOp.NONE, ((1, 1),)), "takes no pairs"),
        (InhibitPolarity(PolarityOp.ENABLE_LOW), "needs at least one station"),
    ],
)
def test_encoder_refuses_values_the_box_cannot_take(command: object, message: str) -> None:
    with pytest.raises(EncodeError, match=message):
        encode(command)  # type: ignore[arg-type]


# --------------------------------------------------------------------------- reading, as the box


@pytest.mark.parametrize(
    ("text", "code"),
    [
        ("x", "U"),
        ("=12", "U"),
        ("!9B1", "A"),
        ("!1Q1", "A"),
        ("!1B", "A"),
        ("!1B1;", "A"),
        ("!0T0", "A"),
        ("%Z", "A"),
        ("%C123", "A"),
        ("(17", "A"),
        ("~11", "T"),
        ("@212", "T"),
        ("[0", "A"),
        ("[12345", "A"),
        ("]100", "A"),
        ("\\7100", "A"),
        ("\\1", "A"),
        ("'x", "A"),
        ("*", "A"),
        ("*Q", "A"),
        ('"X', "A"),
        (":123", "A"),
        ("^E", "A"),
        ("/X1", "A"),
    ],
)
def test_bad_commands_get_the_boxs_error_letter(text: str, code: str) -> None:
    with pytest.raises(CommandRejected) as info:
        parse_command(text)
    assert info.value.code == code
    assert info.value.reason


_stations = st.frozensets(st.integers(1, 6))
_pairs = st.lists(st.tuples(st.integers(0, 63), st.integers(0, 63)), max_size=18).map(tuple)
_commands = st.one_of(
    st.builds(
        SetAntenna, st.integers(1, 6), st.sampled_from(list(AntennaKind)), st.integers(0, 63),
        st.lists(st.integers(0, 63), max_size=MAX_RELAYS).map(tuple),
    ),
    st.builds(ConflictTable, st.sampled_from([ConflictOp.SET, ConflictOp.CLEAR]), _pairs),
    st.builds(FastTable, st.sampled_from([FastOp.FAST, FastOp.SLOW]), _pairs),
    st.builds(Inhibit, _stations),
    st.builds(Uninhibit, _stations),
    st.builds(Mode, st.sampled_from(list(StationMode)), _stations),
    st.builds(InhibitTime, st.integers(1, 9999)),
    st.builds(InterruptDelay, st.integers(0, 99)),
    st.builds(ReceiveDelay, st.integers(1, 6), st.integers(0, 9999)),
    st.builds(SetState, st.lists(st.sampled_from(list(StateOp)), min_size=1, max_size=6).map(tuple)),
    st.builds(SystemTable, st.just(False), _pairs),
    st.builds(UnitId, st.none() | st.integers(0, 99)),
    st.integers(1, 6).flatmap(
        lambda s: st.builds(InhibitOthers, st.just(s), _stations.map(lambda x: x - {s}))
    ),
    st.integers(1, 6).flatmap(
        lambda s: st.builds(UseAlternate, st.just(s), _stations.map(lambda x: x - {s}))
    ),
)


@given(_commands)
def test_any_command_round_trips_through_its_bytes(command: object) -> None:
    data = encode(command)  # type: ignore[arg-type]
    assert len(data) <= MAX_COMMAND
    assert data.endswith(b";")
    assert parse_command(data[:-1].decode()) == command


def test_vendor_extension_carries_its_text() -> None:
    assert encode(VendorExtension("dbg")) == b"#dbg;"
    assert parse_command("#dbg") == VendorExtension("dbg")
