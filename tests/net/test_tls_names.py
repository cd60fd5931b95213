"""The self-signed certificate names the addresses the server listens on, so a phone
that opens the station by its address meets no name mismatch; when they change it is
renewed with the same key (and only then); the addresses a phone can reach leave
loopback out."""

from __future__ import annotations

import ipaddress
from pathlib import Path

import pytest
from cryptography import x509

from moas_gui.addresses import (
    WebPage,
    interface_addresses,
    listen_addresses,
    network_address,
    reachable_addresses,
)
from moas_gui.tls import (
    carried_names,
    default_paths,
    ensure_certificate,
    fingerprint,
    make_self_signed,
)


@pytest.fixture(autouse=True)
def own_config(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "cfg"))


def _public_key(path: Path) -> bytes:
    from cryptography.hazmat.primitives import serialization

    cert = x509.load_pem_x509_certificate(path.read_bytes())
    return cert.public_key().public_bytes(serialization.Encoding.DER,
                                          serialization.PublicFormat.SubjectPublicKeyInfo)


def test_the_certificate_carries_the_addresses_and_names() -> None:
    kept = default_paths()
    make_self_signed(kept, "shack-pc", ["127.0.0.1", "192.0.2.5", "fd00::5"])
    carried = carried_names(kept.cert)
    assert carried == (["localhost", "shack-pc"], ["127.0.0.1", "192.0.2.5", "fd00::5"])


def test_changed_addresses_renew_it_with_the_same_key_and_the_same_do_not() -> None:
    kept = ensure_certificate(addresses=["127.0.0.1"])
    first, key, public = fingerprint(kept), kept.key.read_bytes(), _public_key(kept.cert)
    assert carried_names(kept.cert) is not None
    assert carried_names(kept.cert)[1] == ["127.0.0.1"]  # type: ignore[index]
    assert fingerprint(ensure_certificate(addresses=["127.0.0.1"])) == first  # unchanged
    assert fingerprint(ensure_certificate()) == first  # no addresses given: left alone
    renewed = ensure_certificate(addresses=["127.0.0.1", "192.0.2.7"])
    assert carried_names(renewed.cert)[1] == ["127.0.0.1", "192.0.2.7"]  # type: ignore[index]
    assert fingerprint(renewed) != first
    assert renewed.key.read_bytes() == key and _public_key(renewed.cert) == public


def test_given_files_are_never_renewed(tmp_path: Path) -> None:
    from moas_gui.tls import Certificate

    given = Certificate(tmp_path / "c.pem", tmp_path / "k.pem")
    make_self_signed(given, "localhost")
    before = given.cert.read_bytes()
    ensure_certificate(str(given.cert), str(given.key), ["192.0.2.9"])
    assert given.cert.read_bytes() == before


def test_the_addresses_listened_on_and_those_a_phone_reaches() -> None:
    every = interface_addresses()
    assert every[0] == "127.0.0.1"
    for text in every:
        ipaddress.ip_address(text)  # each one an address
    routed = network_address()
    if routed != "127.0.0.1":  # a computer on a network: its routed address is listed
        assert routed in every
    assert all(":" not in a for a in listen_addresses("0.0.0.0"))
    assert listen_addresses("192.0.2.5") == ["192.0.2.5"]
    assert reachable_addresses("127.0.0.1") == [] and reachable_addresses("::1") == []
    assert reachable_addresses("192.0.2.5") == ["192.0.2.5"]
    on_all = reachable_addresses("0.0.0.0")
    assert all(not ipaddress.ip_address(a).is_loopback for a in on_all)
    assert set(on_all) <= set(every)
    assert WebPage("127.0.0.1", 8080, True).reachable == []
