"""Settings: ``[tool.fuzzoff]`` of the nearest pyproject.toml or a fuzzoff.toml, then the CLI.

Keys (ruff-like): ``px4``, ``vehicle``, ``select``, ``extend-select``, ``ignore``, ``fail-on``,
``severity`` (table code -> level), ``options`` (table code -> table of thresholds),
``params`` (PX4 parameter overrides for the gate model), ``per-file-ignores`` (glob -> codes).
An unknown key, code or option is a usage error, never ignored.

As in ruff, each recording is judged with the nearest configuration above it (a ``rover/``
folder may carry its own ``fuzzoff.toml``); the command line applies on top of every one. A
recording with no configuration above it takes the one found from the current folder.

One idea a module: ``settings`` (the ``Settings`` record, and what one recording is judged
with), ``table`` (a configuration table read and checked), ``discovery`` (which configuration
applies where), ``globs`` (``per-file-ignores`` patterns), ``errors``; release names are
parsed by ``fuzzoff.releases``.
"""

from __future__ import annotations

from fuzzoff.config.discovery import NearestConfig, find_config, load_settings
from fuzzoff.config.errors import ConfigError, did_you_mean
from fuzzoff.config.globs import FileIgnore, glob_regex
from fuzzoff.config.settings import Discovery, Settings
from fuzzoff.config.table import (
    KNOWN_KEYS,
    read_config_table,
    settings_from_table,
    user_px4_profile,
    user_vehicle_type,
)

__all__ = [
    "KNOWN_KEYS",
    "ConfigError",
    "Discovery",
    "FileIgnore",
    "NearestConfig",
    "Settings",
    "did_you_mean",
    "find_config",
    "glob_regex",
    "load_settings",
    "read_config_table",
    "settings_from_table",
    "user_px4_profile",
    "user_vehicle_type",
]
