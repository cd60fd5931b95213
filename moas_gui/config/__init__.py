"""The ``.moas`` configuration: its model, its reader and its checks.

``load_config(path)`` returns a :class:`LoadResult`: a complete :class:`Config`
or every problem, with line and column, and never a half-loaded file.
"""

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

__all__ = [
    "ALL_FREQUENCIES", "FUNCTION_NAMES", "MAX_BYTES", "SERIAL_MODELS", "AlternateRule",
    "Antenna", "Button", "ButtonType", "Config", "ConfigError", "ControlRange",
    "FrequencyRange", "Function", "Layout", "LoadResult", "MatrixEntry", "N1MMStation",
    "Problem", "Radio", "RadioRef", "RelativeAntennas", "RelativeRange", "Rotator",
    "RotatorControl", "Severity", "StationRelays", "Switch", "SwitchPort", "System",
    "Template", "TemplateInfo", "TransmitRelays", "load_config", "parse_config", "read_config",
]
