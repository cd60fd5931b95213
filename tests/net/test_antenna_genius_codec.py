"""The Antenna Genius codec and mapping, sans-IO (issue 32): every line ending, the
list terminator, the numbering of bands, antennas and ports."""

from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path

import pytest

from moas_gui.config import load_config
from moas_gui.config.model import Radio, RadioRef
from moas_gui.net.antenna_genius import codec
from moas_gui.net.antenna_genius.codec import AgCommand, AgMalformed, CommandReader, PortStatus
from moas_gui.net.antenna_genius.discovery import AgAnnouncement, broadcast_targets, parse_target
from moas_gui.net.antenna_genius.mapping import (
    BANDS,
    ag_antennas,
    band_of,
    devices,
    main_radios,
    parse_radios,
    serial_for,
)

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize("ending", [b"\r", b"\n", b"\r\n"])
def test_commands_end_with_cr_lf_or_crlf_alike(ending: bytes) -> None:
    reader = CommandReader()
    stream = b"C1|info get" + ending + b"C2|port get 1" + ending
    # fed a byte at a time, the same commands come out
    out = [item for byte in stream for item in reader.feed(bytes([byte]))]
    assert out == [AgCommand(1, "info get", ("info", "get")),
                   AgCommand(2, "port get 1", ("port", "get", "1"))]


def test_a_crlf_split_between_two_reads_is_one_ending_and_blank_lines_are_skipped() -> None:
    reader = CommandReader()
    assert reader.feed(b"C7|ping\r") == [AgCommand(7, "ping", ("ping",))]
    assert reader.feed(b"\nC8|ping\n\n\r\n") == [AgCommand(8, "ping", ("ping",))]


def test_arguments_are_key_value_words_and_words_are_lower_case() -> None:
    item = codec.parse_line("C12|Port SET 2 auto=0 rxant=3 txant=4 band=5")
    assert isinstance(item, AgCommand)
    assert item.seq == 12 and item.verb == "port set"
    assert item.words == ("port", "set", "2")
    assert item.args == {"auto": "0", "rxant": "3", "txant": "4", "band": "5"}


@pytest.mark.parametrize(("line", "seq"), [("info get", 0), ("C|ping", 0), ("Cx|ping", 0),
                                           ("C5 ping", 5)])
def test_a_line_that_is_not_a_command_says_why_with_its_sequence_number(line: str,
                                                                         seq: int) -> None:
    item = codec.parse_line(line)
    assert isinstance(item, AgMalformed)
    assert item.seq == seq and "not a command line" in item.reason


def test_an_overlong_line_is_one_malformed_item_and_what_follows_is_read() -> None:
    reader = CommandReader()
    out = reader.feed(b"C3|" + b"x" * 2000 + b"\nC4|ping\n")
    assert isinstance(out[0], AgMalformed) and out[0].seq == 3
    assert out[1] == AgCommand(4, "ping", ("ping",))


def test_replies_lists_and_status_lines_have_the_protocols_shapes() -> None:
    assert codec.greeting() == b"V4.1.0 AG\r\n"
    assert codec.greeting(auth=True) == b"V4.1.0 AG AUTH\r\n"
    assert codec.reply(5) == b"R5|0|\r\n"
    assert codec.reply(6, codec.NO_AUTH) == b"R6|FF|\r\n"
    assert codec.reply(7, codec.REFUSED, "no\nway") == b"R7|20|no way\r\n"
    assert codec.list_reply(9, ["a", "b"]) == b"R9|0|a\r\nR9|0|b\r\nR9|0|\r\n"
    assert codec.list_reply(9, []) == b"R9|0|\r\n"
    assert codec.status("antenna reload") == b"S0|antenna reload\r\n"
    assert codec.name_text(" 40 m dipole|x=y ") == "40_m_dipole_x_y"


def test_port_status_line() -> None:
    line = PortStatus(1, auto=False, source="MANUAL", band=6, rxant=4, txant=1, tx=True,
                      inhibit=True, freq_mhz=14.025, nickname="S1R1").text()
    assert line == ("port 1 auto=0 source=MANUAL band=6 rxant=4 txant=1 tx=1 inhibit=1 "
                    "freq=14.025000 nickname=S1R1")
    assert PortStatus(2).text() == "port 2 auto=1 source=AUTO band=0 rxant=0 txant=0 tx=0 inhibit=0"


def test_sixteen_bands_from_160_to_6_m_and_band_of_a_frequency() -> None:
    assert len(BANDS) == 16 and [b.number for b in BANDS] == list(range(16))
    assert [b.name for b in BANDS[1:12]] == ["160m", "80m", "60m", "40m", "30m", "20m", "17m",
                                             "15m", "12m", "10m", "6m"]
    assert BANDS[6].text() == "band 6 name=20m freq_start=14.000000 freq_stop=14.350000"
    assert band_of(14025) == 6 and band_of(50100) == 11 and band_of(1850) == 1
    assert band_of(None) == 0 and band_of(13000) == 0 and band_of(0) == 0
    for band in BANDS[1:12]:
        assert band_of(band.middle_khz) == band.number


def test_antennas_are_numbered_in_the_configurations_order_with_band_masks() -> None:
    config = load_config(EXAMPLES / "small-station.moas").unwrap()
    listed = ag_antennas(config)
    assert [a.number for a in listed] == [1, 2, 3, 4]
    assert [a.id for a in listed] == [a.id for a in config.antennas]
    tri = listed[0]
    assert tri.text() == "antenna 1 name=Triband_Yagi_20-15-10 tx=0540 rx=0540 inband=0000"
    assert tri.tx == (1 << 6) | (1 << 8) | (1 << 10)  # 20, 15, 10 m
    assert listed[2].tx == 1 << 2  # 80 m
    vertical = listed[3]
    assert vertical.tx == sum(1 << n for n in (1, 2, 4, 5, 6, 7, 8, 9, 10))  # no 60 m, no 6 m


def test_rx_only_antennas_have_no_tx_bits_and_disabled_ones_none(tmp_path: Path) -> None:
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Antennas"][2]["RXOnly"] = True
    data["Antennas"][1]["Enabled"] = False
    path = tmp_path / "s.moas"
    path.write_text(json.dumps(data))
    result = load_config(path)
    listed = ag_antennas(result.unwrap())
    assert listed[2].tx == 0 and listed[2].rx == 1 << 2
    assert listed[1].tx == 0 and listed[1].rx == 0


def test_ports_are_the_first_two_main_radios_or_the_chosen_ones_two_per_device() -> None:
    small = load_config(EXAMPLES / "small-station.moas").unwrap()
    config = replace(small, radios=(*small.radios, Radio(2, 1), Radio(2, 2, sub_receiver=3),
                                    Radio(2, 3)))
    mains = main_radios(config)
    assert mains == (RadioRef(1, 1), RadioRef(1, 2), RadioRef(2, 1), RadioRef(2, 2))
    (first,) = devices(config)
    assert first.radios == mains[:2] and first.port_of(mains[1]) == 2
    chosen = devices(config, mains[:3])
    assert [d.radios for d in chosen] == [mains[:2], (mains[2], None)]
    assert chosen[1].radio(1) == mains[2] and chosen[1].radio(2) is None
    assert chosen[1].radio(3) is None
    with pytest.raises(ValueError, match="no main radio station 99 radio 1"):
        devices(config, (RadioRef(99, 1),))


def test_ag_radios_text_and_serials() -> None:
    assert parse_radios("1/1, 2/1") == (RadioRef(1, 1), RadioRef(2, 1))
    with pytest.raises(ValueError, match="'1-1' is not STATION/RADIO"):
        parse_radios("1-1")
    assert serial_for("MOAS_x", 9007) == serial_for("MOAS_x", 9007)
    assert serial_for("MOAS_x", 9007) != serial_for("MOAS_x", 9008)
    assert len(serial_for("MOAS_x", 9007).split("-")) == 3


def test_discovery_line_and_targets() -> None:
    text = AgAnnouncement(9007, "4.1.0", "AB-CD-EF", "MOAS_x", 2, 4, 12).text("127.0.0.1")
    assert text == ("AG ip=127.0.0.1 port=9007 v=4.1.0 serial=AB-CD-EF name=MOAS_x ports=2 "
                    "antennas=4 mode=master uptime=12")
    assert broadcast_targets("127.0.0.1") == []
    assert broadcast_targets("::1") == []
    assert all(not ip.startswith("127.") for ip, _ in broadcast_targets("0.0.0.0"))
    assert parse_target("127.0.0.1:9007") == ("127.0.0.1", 9007)
    with pytest.raises(ValueError, match="not ADDR:PORT"):
        parse_target("127.0.0.1")
    with pytest.raises(ValueError, match="not an IP address"):
        parse_target("example:9007")


def test_a_port_set_becomes_the_engines_operations_in_order() -> None:
    from moas_gui.engine.operations import Hold, Select, SetFrequency
    from moas_gui.engine_backend import operations
    from moas_gui.net.antenna_genius.server import PortRequest

    before = time.time()
    ops = operations(PortRequest(1, 2, release=True, khz=14175.0, tx=3, rx=3, hold_by="x"))
    held = ops[-1]
    assert isinstance(held, Hold) and held.since is not None
    assert before <= held.since <= time.time()  # the wall clock: "held since 09:14"
    assert ops == [
        Hold(1, 2, None), SetFrequency(1, 2, 14175.0), Select(1, 2, 3, "both", True),
        Hold(1, 2, "x", since=held.since)]
    assert operations(PortRequest(1, 1, tx=0, rx=2)) == [Select(1, 1, 0, "tx", True),
                                                        Select(1, 1, 2, "rx", True)]
    assert operations(PortRequest(1, 1, rx=2)) == [Select(1, 1, 2, "rx", True)]
    assert operations(PortRequest(1, 1)) == []


def test_an_engines_sentence_in_the_ags_words() -> None:
    from moas_gui.net.antenna_genius.mapping import ag_words

    config = load_config(EXAMPLES / "small-station.moas").unwrap()
    antennas = ag_antennas(config)
    device = devices(config)[0]
    # the engine's "Antenna <ID> (<label>)" and a title alone both become the AG's number
    # and antenna-list name; a radio on this device gets its port, another none
    assert ag_words("Antenna 2 (80 Dipole) does not cover 14025 kHz for station 1 radio 1",
                    antennas, device) == ("AG antenna 3 (80_m_dipole) does not cover 14025 kHz"
                                          " for station 1 radio 1 (port 1)")
    assert ag_words("All-band vertical is in use by Station 2 radio 1", antennas, device) \
        == "AG antenna 4 (All-band_vertical) is in use by Station 2 radio 1"
    assert ag_words("Antenna 0 (Tribander) and Antenna 1 (40 Dipole)", antennas) \
        == "AG antenna 1 (Triband_Yagi_20-15-10) and AG antenna 2 (40_m_dipole_(also_15_m))"
    assert ag_words("nothing to say", antennas, device) == "nothing to say"
