"""Reading numbers from the wire: only ASCII counts."""

from __future__ import annotations


def is_digits(text: str) -> bool:
    """True for one or more of the ASCII digits 0-9 (``str.isdigit`` also takes '²')."""
    return text.isascii() and text.isdigit()


__all__ = ["is_digits"]
