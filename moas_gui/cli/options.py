"""Command-line options the programs share, so that each is written the same way."""

from __future__ import annotations

import argparse
import logging

LOG_LEVELS: dict[str, int] = {"debug": logging.DEBUG, "info": logging.INFO,
                              "warning": logging.WARNING, "error": logging.ERROR}
"""``--log-level`` words (any case), from the most to the least said."""


def _log_level(text: str) -> str:
    word = text.strip().lower()
    if word not in LOG_LEVELS:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not one of {', '.join(LOG_LEVELS)} (in any case)")
    return word


def add_log_level(parser: argparse.ArgumentParser, default: str, what: str) -> None:
    """``--log-level LEVEL``: debug, info, warning or error, in any case (stored lower case)."""
    parser.add_argument("--log-level", type=_log_level, default=default, metavar="LEVEL",
                        help=f"{what}: debug, info, warning or error, in any case "
                             f"(default {default})")


def log_level_number(word: str) -> int:
    """The :mod:`logging` level of a ``--log-level`` word."""
    return LOG_LEVELS[word]


__all__ = ["LOG_LEVELS", "add_log_level", "log_level_number"]
