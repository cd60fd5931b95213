"""HOST[:PORT] as an operator types it on the moas-client command line."""

from __future__ import annotations

import pytest

from moas_gui.client.address import parse_address


@pytest.mark.parametrize(("text", "expected"), [
    (None, ("127.0.0.1", 12059)),
    ("", ("127.0.0.1", 12059)),
    ("shack-pc", ("shack-pc", 12059)),
    ("10.0.0.5:12060", ("10.0.0.5", 12060)),
    ("[fe80::1]:2000", ("fe80::1", 2000)),
    ("[::1]", ("::1", 12059)),
    ("::1", ("::1", 12059)),
])
def test_addresses_people_type(text: str | None, expected: tuple[str, int]) -> None:
    assert parse_address(text) == expected


@pytest.mark.parametrize(("text", "words"), [
    ("host:port", "the port 'port' is not a number from 1 to 65535"),
    ("host:70000", "the port '70000' is not a number from 1 to 65535"),
    ("host:", "the port after ':' is empty"),
    (":12059", "the host name is empty"),
    ("[::1", "has no ']'"),
    ("[::1]x", "expected ':PORT' after ']'"),
])
def test_mistakes_are_explained(text: str, words: str) -> None:
    with pytest.raises(ValueError, match=words.replace("[", r"\[").replace("]", r"\]")):
        parse_address(text)
