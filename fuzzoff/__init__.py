"""fuzzoff: lint and fuzz PX4 offboard setpoint streams.

The typed API the CLI is a thin layer over::

    import fuzzoff
    report = fuzzoff.lint_file("flight.tlog", fuzzoff.Settings(px4="1.15"))
    for finding in report.findings:
        print(finding.time_s, finding.code, finding.message)
"""

from __future__ import annotations

from fuzzoff._version import __version__
from fuzzoff.config import ConfigError, Settings, load_settings
from fuzzoff.engine import lint_file, lint_paths, run_events
from fuzzoff.findings import FileReport, Finding, Report, Severity
from fuzzoff.profiles import Profile

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
