"""Keeping a repeating fault from writing the log without bound: see
:mod:`moas_gui.edge.log_limit` (every listener of the program shares it)."""

from __future__ import annotations

from moas_gui.edge.log_limit import LOG_INTERVAL, LogLimiter, held_text

__all__ = ["LOG_INTERVAL", "LogLimiter", "held_text"]
