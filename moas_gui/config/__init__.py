"""The ``.moas`` configuration: its model, its reader and its checks.

``load_config(path)`` returns a :class:`LoadResult`: a complete :class:`Config`
or every problem, with line and column, and never a half-loaded file.

The package's names are imported from their modules when first asked for: a program
that needs one part (the rig entries' rules in :mod:`.rigs`, the problems of
:mod:`.problems`) does not load the model and the reader with it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .loader import MAX_BYTES, LoadResult, load_config, parse_config, read_config
    from .model import (
        ALL_FREQUENCIES,
        FUNCTION_NAMES,
        AlternateRule,
        Antenna,
        Button,
        ButtonType,
        Config,
        ControlRange,
        FrequencyRange,
        Function,
        Layout,
        MatrixEntry,
        N1MMStation,
        Radio,
        RadioRef,
        RelativeAntennas,
        RelativeRange,
        Rotator,
        RotatorControl,
        StationRelays,
        Switch,
        SwitchPort,
        System,
        Template,
        TemplateInfo,
        TransmitRelays,
    )
    from .problems import ConfigError, Problem, Severity
    from .validate import SERIAL_MODELS

_FROM_MODEL = (
    "ALL_FREQUENCIES", "FUNCTION_NAMES", "AlternateRule", "Antenna", "Button", "ButtonType",
    "Config", "ControlRange", "FrequencyRange", "Function", "Layout", "MatrixEntry",
    "N1MMStation", "Radio", "RadioRef", "RelativeAntennas", "RelativeRange", "Rotator",
    "RotatorControl", "StationRelays", "Switch", "SwitchPort", "System", "Template",
    "TemplateInfo", "TransmitRelays",
)
_WHERE: dict[str, str] = {
    **dict.fromkeys(("MAX_BYTES", "LoadResult", "load_config", "parse_config", "read_config"),
                    "loader"),
    **dict.fromkeys(_FROM_MODEL, "model"),
    **dict.fromkeys(("ConfigError", "Problem", "Severity"), "problems"),
    "SERIAL_MODELS": "validate",
}
"""The module of each name the package hands out."""


def __getattr__(name: str) -> object:
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from importlib import import_module

    return getattr(import_module(f"{__name__}.{where}"), name)


__all__ = [
    "ALL_FREQUENCIES", "FUNCTION_NAMES", "MAX_BYTES", "SERIAL_MODELS", "AlternateRule",
    "Antenna", "Button", "ButtonType", "Config", "ConfigError", "ControlRange",
    "FrequencyRange", "Function", "Layout", "LoadResult", "MatrixEntry", "N1MMStation",
    "Problem", "Radio", "RadioRef", "RelativeAntennas", "RelativeRange", "Rotator",
    "RotatorControl", "Severity", "StationRelays", "Switch", "SwitchPort", "System",
    "Template", "TemplateInfo", "TransmitRelays", "load_config", "parse_config", "read_config",
]
