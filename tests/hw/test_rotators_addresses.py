"""Address strings: host, host:port, [v6]:port; which hosts are this computer."""

from __future__ import annotations

import pytest

from moas_gui.hw.rotators.addresses import is_local, split_address


@pytest.mark.parametrize(("text", "expected"), [
    ("192.168.1.20", ("192.168.1.20", 9006)),
    ("genius.local:9010", ("genius.local", 9010)),
    (" 10.0.0.5:4533 ", ("10.0.0.5", 4533)),
    ("[::1]:4535", ("::1", 4535)),
    ("[fe80::1]", ("fe80::1", 9006)),
    ("::1", ("::1", 9006)),
])
def test_addresses_give_host_and_port(text: str, expected: tuple[str, int]) -> None:
    assert split_address(text, 9006) == expected


@pytest.mark.parametrize(("text", "why"), [
    ("", "empty"),
    ("host:0", "1 to 65535"),
    ("host:http", "1 to 65535"),
    ("[::1", "has no"),
    ("[::1]x", "after ']'"),
    (":4533", "host name"),
    ("two words:4533", "host name"),
])
def test_bad_addresses_are_refused_with_a_sentence(text: str, why: str) -> None:
    with pytest.raises(ValueError, match=why):
        split_address(text, 4533)


@pytest.mark.parametrize(("host", "local"), [
    ("127.0.0.1", True), ("127.1.2.3", True), ("::1", True), ("LocalHost", True),
    ("192.168.1.2", False), ("station-pc", False), ("0.0.0.0", False),
])
def test_this_computer_is_loopback_or_localhost(host: str, local: bool) -> None:
    assert is_local(host) is local
