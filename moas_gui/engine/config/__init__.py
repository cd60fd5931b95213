"""The ``.moas`` configuration: its model, its reader and its checks.

``load_config(path)`` returns a :class:`LoadResult`: a complete :class:`Config`
or every problem, with line and column, and never a half-loaded file.
"""

from .loader import MAX_BYTES, LoadResult, load_config, parse_config
from .model import *  # noqa: F403
from .model import __all__ as _model_names
from .problems import ConfigError, Problem, Severity
from .validate import SERIAL_MODELS

__all__ = [
    "ConfigError", "LoadResult", "MAX_BYTES", "Problem", "SERIAL_MODELS", "Severity",
    "load_config", "parse_config", *_model_names,
]
