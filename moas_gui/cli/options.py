"""Command-line options the programs share, so that each is written the same way."""

from __future__ import annotations

import argparse
import logging
import os
import sys

LOG_LEVELS: dict[str, int] = {"debug": logging.DEBUG, "info": logging.INFO,
                              "warning": logging.WARNING, "error": logging.ERROR}
"""``--log-level`` words (any case), from the most to the least said."""


def terminal_columns(fallback: int = 80) -> int:
    """The width help text is wrapped to: the ``COLUMNS`` variable when it holds a positive
    number, else the width of the terminal standard output is on, else ``fallback`` (what
    :func:`shutil.get_terminal_size` answers, without loading :mod:`shutil`, which brings
    the bz2 and lzma compressors: 4 ms of each program's start)."""
    try:
        columns = int(os.environ.get("COLUMNS", "0"))
    except ValueError:
        columns = 0
    if columns > 0:
        return columns
    stream = sys.__stdout__
    try:
        columns = os.get_terminal_size(stream.fileno()).columns if stream is not None else 0
    except (AttributeError, ValueError, OSError):
        columns = 0
    return columns or fallback


class HelpFormatter(argparse.HelpFormatter):
    """argparse's help layout, wrapped to :func:`terminal_columns` less two (as argparse
    does).  argparse makes a formatter for every ``add_argument`` (to check its metavar),
    and its own asks :mod:`shutil` for the width each time; every program's parser is made
    with this one instead."""

    def __init__(self, prog: str, indent_increment: int = 2, max_help_position: int = 24,
                 width: int | None = None) -> None:
        super().__init__(prog, indent_increment, max_help_position,
                         terminal_columns() - 2 if width is None else width)


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


__all__ = ["LOG_LEVELS", "HelpFormatter", "add_log_level", "log_level_number", "terminal_columns"]
