"""fuzzoff: lint and fuzz PX4 offboard setpoint streams.

The typed API the CLI is a thin layer over::

    import fuzzoff
    report = fuzzoff.lint_file("flight.tlog", fuzzoff.Settings(px4="1.15"))
    for finding in report.findings:
        print(finding.time_s, finding.code, finding.message)

The names are imported when first used (PEP 562), so that ``import fuzzoff.cli`` and
``fuzzoff --version`` do not pay for the engine, the gate model and the rule catalog.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from fuzzoff._version import __version__

if TYPE_CHECKING:
    from fuzzoff.config import Settings, load_settings
    from fuzzoff.engine import lint_file, lint_paths, run_events
    from fuzzoff.findings import FileReport, Finding, Report, Severity
    from fuzzoff.profiles import Profile
    from fuzzoff.usage import ConfigError

_HOMES = {
    "ConfigError": "fuzzoff.usage",
    "FileReport": "fuzzoff.findings",
    "Finding": "fuzzoff.findings",
    "Profile": "fuzzoff.profiles",
    "Report": "fuzzoff.findings",
    "Settings": "fuzzoff.config",
    "Severity": "fuzzoff.findings",
    "lint_file": "fuzzoff.engine",
    "lint_paths": "fuzzoff.engine",
    "load_settings": "fuzzoff.config",
    "run_events": "fuzzoff.engine",
}
"""Each public name -> the module that defines it."""

__all__ = [
    "ConfigError",
    "FileReport",
    "Finding",
    "Profile",
    "Report",
    "Settings",
    "Severity",
    "__version__",
    "lint_file",
    "lint_paths",
    "load_settings",
    "run_events",
]


def __getattr__(name: str) -> Any:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'fuzzoff' has no attribute {name!r}")
    value = getattr(importlib.import_module(home), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
