"""Frequency sources: loggers and rig daemons that say what each radio does.

Each source is a sans-IO parser plus a thin asyncio part; all share
:mod:`moas_gui.sources.base` (events, the Source shape, the reconnect and
"newest wins" rules).  See docs/sources.md.
"""
