"""The antenna log as ADIF: written by moas_gui.antenna_log.adif, read back by the real
``adif-io`` library (PyPI), every field compared."""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

import adif_io
import pytest
from antenna_log_support import T0, MemoryJournal, contact, contest_journal

from moas_gui import __version__
from moas_gui.antenna_log.adif import adif_band, adif_mode, adif_text, parse_utc, write_adif
from moas_gui.antenna_log.records import Period

WHOLE = Period(T0 - 10, T0 + 10 * 3600)


def read_back(path: Path) -> tuple[list[adif_io.QSO], adif_io.Headers]:
    return adif_io.read_from_file(str(path))


def test_every_field_of_every_contact_reads_back(tmp_path: Path) -> None:
    journal = contest_journal()
    out = tmp_path / "contest.adi"
    count = write_adif(journal, WHOLE, out, station_callsign="k1xx")
    qsos, headers = read_back(out)
    assert count == len(journal.contacts_) == len(qsos) == 15
    assert headers["ADIF_VER"] == "3.1.4"
    assert headers["PROGRAMID"] == "moas-gui"
    assert headers["PROGRAMVERSION"] == __version__
    created = datetime.strptime(headers["CREATED_TIMESTAMP"], "%Y%m%d %H%M%S")
    assert abs(created.replace(tzinfo=UTC).timestamp() - datetime.now(UTC).timestamp()) < 3600
    for qso, c in zip(qsos, journal.contacts_, strict=True):
        when = datetime.fromtimestamp(c.time, UTC)
        expected = {
            "CALL": c.call,
            "QSO_DATE": when.strftime("%Y%m%d"),
            "TIME_ON": when.strftime("%H%M%S"),
            "BAND": "20m" if c.band == "14" else "40m",
            "MODE": "CW",
            "FREQ": "14.025" if c.tx_khz == 14025 else f"{c.tx_khz / 1000:g}",
            "OPERATOR": "K1AB",
            "CONTEST_ID": "CQ-WW-CW",
            "STATION_CALLSIGN": "K1XX",
            "MY_ANTENNA": c.tx_antenna,
            "APP_MOAS_TXANT": c.tx_antenna,
            "APP_MOAS_RXANT": c.rx_antenna,
        }
        if c.heading is not None:
            expected["ANT_AZ"] = "45"
        assert dict(qso) == expected
        assert adif_io.time_on(qso).timestamp() == c.time


def test_fields_with_nothing_to_say_are_left_out_and_the_rest_kept() -> None:
    c = contact(1, T0 + 61.7, "ok1abc", "7", "USB", radio=None, khz=None, operator="", contest="")
    qsos, _ = adif_io.read_from_string(adif_text([c]))
    when = datetime.fromtimestamp(T0 + 61, UTC)  # the seconds are whole: 61.7 is 61
    assert dict(qsos[0]) == {
        "CALL": "OK1ABC",
        "QSO_DATE": when.strftime("%Y%m%d"),
        "TIME_ON": when.strftime("%H%M%S"),
        "BAND": "40m",
        "MODE": "SSB",
        "SUBMODE": "USB",
    }


def test_split_frequencies_heading_and_switch_path() -> None:
    c = contact(
        1,
        T0,
        "W1AW",
        "21",
        "CW",
        tx="Stack 15 (both)",
        rx="Stack 15 top",
        khz=21025.5,
        rx_khz=21027.25,
        heading=359.96,
        path="R1 -> Stack 15 BIP",
    )
    qso = adif_io.read_from_string(adif_text([c]))[0][0]
    assert qso["FREQ"] == "21.0255"
    assert qso["FREQ_RX"] == "21.02725"
    assert qso["ANT_AZ"] == "0"  # 359.96 rounds to 360, which is north
    assert qso["MY_ANTENNA"] == "Stack 15 (both)"
    assert qso["APP_MOAS_RXANT"] == "Stack 15 top"
    assert qso["APP_MOAS_SWITCH_PATH"] == "R1 -> Stack 15 BIP"


def test_lengths_count_characters_not_bytes(tmp_path: Path) -> None:
    # names in other scripts, an emoji (one character, four bytes), and a '<' that must
    # not end the field: the next field still reads whole
    names = ["Süd-Yagi", "Антенна 40", "八木 15", "Loop 🛰 <EOR>"]
    journal = MemoryJournal(
        [
            contact(
                i, T0 + i, "DL1ABC", tx=name, rx=name[::-1], operator="dl1abc", path=f"{name}/ä"
            )
            for i, name in enumerate(names)
        ]
    )
    out = tmp_path / "intl.adi"
    write_adif(journal, WHOLE, out)
    assert "<MY_ANTENNA:8>Süd-Yagi " in out.read_text(encoding="utf-8")
    qsos, _ = read_back(out)
    assert [q["MY_ANTENNA"] for q in qsos] == names
    assert [q["APP_MOAS_RXANT"] for q in qsos] == [name[::-1] for name in names]
    assert [q["APP_MOAS_SWITCH_PATH"] for q in qsos] == [f"{name}/ä" for name in names]
    assert all(q["OPERATOR"] == "DL1ABC" for q in qsos)


def test_line_breaks_in_a_value_become_spaces() -> None:
    c = contact(1, T0, "N1MM", tx="Yagi\r\n20\tm")
    qso = adif_io.read_from_string(adif_text([c]))[0][0]
    assert qso["MY_ANTENNA"] == "Yagi 20 m"


def test_only_the_period_asked_for_is_written(tmp_path: Path) -> None:
    journal = contest_journal()
    out = tmp_path / "hour.adi"
    assert write_adif(journal, Period(T0, T0 + 3600), out) == 10
    qsos, _ = read_back(out)
    assert all(adif_io.time_on(q).timestamp() < T0 + 3600 for q in qsos)


def test_an_empty_period_is_a_header_alone(tmp_path: Path) -> None:
    out = tmp_path / "none.adi"
    assert write_adif(contest_journal(), Period(0, 1), out) == 0
    qsos, headers = read_back(out)
    assert qsos == [] and headers["ADIF_VER"] == "3.1.4"


def test_an_unwritable_file_raises_and_leaves_nothing(tmp_path: Path) -> None:
    with pytest.raises(OSError):
        write_adif(contest_journal(), WHOLE, tmp_path / "missing-dir" / "x.adi")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("band", "khz", "expected"),
    [
        ("1.8", None, "160m"),
        ("3.5", None, "80m"),
        ("5", None, "60m"),
        ("7", None, "40m"),
        ("10", None, "30m"),
        ("14", None, "20m"),
        ("18", None, "17m"),
        ("21", None, "15m"),
        ("24", None, "12m"),
        ("28", None, "10m"),
        ("50", None, "6m"),
        ("144", None, "2m"),
        ("432", None, "70cm"),
        ("20M", None, "20m"),
        ("1.25m", None, "1.25m"),
        ("", 7025.0, "40m"),
        ("?", 28400.0, "10m"),
        ("", None, ""),
        ("", 9000.0, ""),
    ],
)
def test_bands_as_loggers_write_them(band: str, khz: float | None, expected: str) -> None:
    assert adif_band(band, khz) == expected


@pytest.mark.parametrize(
    ("mode", "expected"),
    [
        ("CW", ("CW", "")),
        ("usb", ("SSB", "USB")),
        ("LSB", ("SSB", "LSB")),
        ("FT8", ("FT8", "")),
        ("FT4", ("MFSK", "FT4")),
        ("RTTY", ("RTTY", "")),
        ("PSK31", ("PSK", "PSK31")),
    ],
)
def test_modes_as_adif_names_them(mode: str, expected: tuple[str, str]) -> None:
    assert adif_mode(mode) == expected


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("2026-11-28T14:00Z", datetime(2026, 11, 28, 14, tzinfo=UTC)),
        ("2026-11-28T14:00:30+00:00", datetime(2026, 11, 28, 14, 0, 30, tzinfo=UTC)),
        ("2026-11-28 14:00", datetime(2026, 11, 28, 14, tzinfo=UTC)),
        ("2026-11-28", datetime(2026, 11, 28, tzinfo=UTC)),
        ("2026-11-28T15:00+01:00", datetime(2026, 11, 28, 14, tzinfo=UTC)),
    ],
)
def test_times_in_iso_8601(text: str, expected: datetime) -> None:
    assert parse_utc(text) == expected.timestamp()


@pytest.mark.parametrize("text", ["yesterday", "2026-13-01", "", "14:00"])
def test_a_bad_time_says_how_to_write_one(text: str) -> None:
    with pytest.raises(ValueError, match="ISO 8601 in UTC, e.g. 2026-11-28T14:00Z"):
        parse_utc(text)
