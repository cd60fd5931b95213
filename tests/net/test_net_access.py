"""Who may connect: the pure access rules of moas_gui.net.access."""

from __future__ import annotations

import ipaddress

import pytest
from hypothesis import given
from hypothesis import strategies as st

from moas_gui.net.access import (
    DEFAULT_ALLOW,
    allowed_networks,
    is_allowed,
    parse_allow_list,
    peer_address,
)

LOCAL = [
    "127.0.0.1", "127.255.255.254", "::1",
    "10.0.0.1", "10.255.255.255",
    "172.16.0.1", "172.20.5.5", "172.31.255.254",
    "192.168.0.1", "192.168.1.20", "192.168.255.255",
    "169.254.0.1", "169.254.100.7",
    "fe80::1", "fe80::1%eth0", "febf:ffff::1",
    "fc00::1", "fd12:3456:789a::1",
    "::ffff:192.168.1.20", "::ffff:10.1.2.3", "::ffff:127.0.0.1",
]
PUBLIC = [
    "8.8.8.8", "1.1.1.1", "203.0.113.7", "198.51.100.1",
    "172.15.255.255", "172.32.0.0", "11.0.0.1", "9.255.255.255",
    "192.167.255.255", "192.169.0.0", "169.253.255.255", "169.255.0.0",
    "128.0.0.1", "0.0.0.0", "255.255.255.255", "224.0.0.1",
    "2001:db8::1", "2606:4700:4700::1111", "fec0::1", "fe00::1", "fe7f::1",
    "::", "::2", "::ffff:8.8.8.8", "64:ff9b::808:808",
]
NOT_ADDRESSES = ["", "localhost", "example.org", "1.2.3", "1.2.3.4.5", "300.1.1.1",
                 "::g", "192.168.1.1/24", "[::1]", " ", "fe80::1%"]


@pytest.mark.parametrize("address", LOCAL)
def test_local_addresses_are_allowed_by_default(address: str) -> None:
    assert is_allowed(address)


@pytest.mark.parametrize("address", PUBLIC)
def test_public_addresses_are_refused_by_default(address: str) -> None:
    assert not is_allowed(address)


@pytest.mark.parametrize("address", NOT_ADDRESSES)
def test_something_that_is_not_an_address_is_refused(address: str) -> None:
    assert not is_allowed(address, parse_allow_list(["0.0.0.0/0", "::/0"]))


def test_an_allow_list_replaces_the_default() -> None:
    allowed = parse_allow_list(["203.0.113.0/24", "2001:db8::5"])
    assert is_allowed("203.0.113.99", allowed)
    assert is_allowed("2001:db8::5", allowed)
    assert not is_allowed("2001:db8::6", allowed)
    assert not is_allowed("127.0.0.1", allowed)
    assert not is_allowed("192.168.1.20", allowed)


def test_a_bare_address_in_the_allow_list_is_a_network_of_one() -> None:
    allowed = parse_allow_list(["192.168.1.20"])
    assert is_allowed("192.168.1.20", allowed)
    assert not is_allowed("192.168.1.21", allowed)


def test_host_bits_in_a_network_are_forgiven() -> None:
    allowed = parse_allow_list(["192.168.7.99/24"])
    assert is_allowed("192.168.7.1", allowed)
    assert not is_allowed("192.168.8.1", allowed)


def test_an_empty_allow_list_lets_nobody_in() -> None:
    allowed = allowed_networks([])
    assert allowed == ()
    assert not is_allowed("127.0.0.1", allowed)
    assert not is_allowed("::1", allowed)


def test_no_allow_list_means_the_default_networks() -> None:
    assert allowed_networks(None) == DEFAULT_ALLOW


def test_an_ipv4_entry_covers_the_same_client_on_a_dual_stack_socket() -> None:
    allowed = parse_allow_list(["203.0.113.0/24"])
    assert is_allowed("::ffff:203.0.113.5", allowed)


def test_ipv4_and_ipv6_never_match_each_other_by_accident() -> None:
    assert not is_allowed("::a00:1", parse_allow_list(["10.0.0.0/8"]))
    assert not is_allowed("10.0.0.1", parse_allow_list(["::/0"]))


@pytest.mark.parametrize("entry", ["localhost", "192.168.1.0/33", "10.0.0.0/8/8", "", "x::y"])
def test_a_bad_allow_entry_is_named_in_the_error(entry: str) -> None:
    with pytest.raises(ValueError, match="ClientAllow entry") as caught:
        parse_allow_list(["10.0.0.0/8", entry])
    assert repr(entry) in str(caught.value)


def test_an_allow_entry_that_is_not_a_string_is_refused() -> None:
    with pytest.raises(TypeError, match="not a string"):
        parse_allow_list([17])  # type: ignore[list-item]


def test_peer_address_drops_the_zone_and_unwraps_ipv4_mapped_addresses() -> None:
    assert peer_address("fe80::1%eth0") == ipaddress.ip_address("fe80::1")
    assert peer_address("::ffff:192.168.1.20") == ipaddress.ip_address("192.168.1.20")
    assert peer_address("nonsense") is None


def _private_by_arithmetic(value: int) -> bool:
    a, b = value >> 24, (value >> 16) & 0xFF
    return (a in (10, 127) or (a == 172 and 16 <= b <= 31) or (a == 192 and b == 168)
            or (a == 169 and b == 254))


@given(st.integers(min_value=0, max_value=2**32 - 1))
def test_every_ipv4_address_is_judged_as_the_private_ranges_say(value: int) -> None:
    text = str(ipaddress.IPv4Address(value))
    assert is_allowed(text) == _private_by_arithmetic(value)
    assert is_allowed("::ffff:" + text) == _private_by_arithmetic(value)


@given(st.integers(min_value=0, max_value=2**128 - 1))
def test_every_ipv6_address_is_judged_by_its_prefix(value: int) -> None:
    address = ipaddress.IPv6Address(value)
    if address.ipv4_mapped is not None:
        expected = _private_by_arithmetic(int(address.ipv4_mapped))
    else:
        expected = (value >> 118 == 0b1111111010  # fe80::/10
                    or value >> 121 == 0b1111110  # fc00::/7
                    or value == 1)  # ::1
    assert is_allowed(str(address)) == expected
