"""``fuzzoff mcp``: an MCP server on standard input and output, so that a coding assistant can
ask fuzzoff about a flight instead of guessing from the raw log (issue 30 item 4).

Four read-only tools: ``lint`` (a recording or folder: the JSON report of docs/reports.md),
``gate`` (the gate model's timeline of one recording), ``rule`` (a rule's page, or every rule
in one line each) and ``profiles`` (the PX4 versions and vehicle types modelled). No tool writes
a file or reaches the network: they read the recordings named and fuzzoff's own catalog. The
server is the official ``mcp`` SDK's, an optional extra: ``pip install 'fuzzoff[mcp]'``.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from fuzzoff.commands import add_command
from fuzzoff.config import ConfigError

INSTRUCTIONS = (
    "fuzzoff judges PX4 offboard setpoint streams in flight recordings (tlog, ULog, MCAP, ROS 2 "
    "and ROS 1 bags) against PX4's own behaviour per release. Use lint for the findings of a "
    "recording or a folder, gate for what PX4 would do step by step, rule CODE for what a "
    "finding means and how to fix the client code, profiles for the releases modelled."
)


def add_parser(sub: Any) -> None:
    parser = add_command(sub, "mcp")
    parser.set_defaults(run=run)


def _settings(px4: str | None, vehicle: str | None) -> Any:
    from fuzzoff.config import load_settings

    overrides = {"px4": px4 or None, "vehicle": vehicle or None}
    return load_settings(Path.cwd(), overrides, per_recording=True)


def lint_tool(path: str, px4: str | None = None, vehicle: str | None = None) -> dict[str, Any]:
    """Lint a recording, a bag folder or a folder of recordings: fuzzoff's JSON report (each
    file's format, profile, findings with code, severity, message, time, place) and the exit
    status fuzzoff lint would give (0 passed, 1 findings at the fail level, 2 unreadable)."""
    from fuzzoff.engine import lint_each, plan_lint
    from fuzzoff.report.json_report import report_dict

    if not Path(path).exists():
        raise ConfigError(f"no such file or folder: {path}")
    settings = _settings(px4, vehicle)
    report = lint_each(plan_lint([path], settings))
    if not report.files:
        raise ConfigError(f"no recordings in {path}")
    return {**report_dict(report), "exit_status": settings.exit_status(report)}


def gate_tool(path: str, px4: str | None = None, vehicle: str | None = None) -> dict[str, Any]:
    """The gate model's timeline of one recording: per vehicle, what PX4 would do (signal,
    requests and their answer, failsafes, controllers) beside the recorded mode, each row with
    the docs/gate.md section that explains it, and where the recording and the model differ."""
    from fuzzoff.gate_timeline import gate_report

    if not Path(path).is_file() and not Path(path).is_dir():
        raise ConfigError(f"no such file or folder: {path}")
    report, rows = gate_report(path, _settings(px4, vehicle).resolved_for(path))
    return {
        "path": report.path,
        "format": report.format,
        "profile": report.to_json()["profile"],
        "complete": report.complete,
        "problems": list(report.problems),
        "vehicles": [
            {
                "vehicle": vehicle_id,
                "timeline": vrows,
                "disagreements": [r for r in vrows if r["what"] == "disagreement"],
            }
            for vehicle_id, vrows in rows.items()
        ],
    }


def rule_tool(code: str | None = None) -> str:
    """A rule's page (what it checks, why, what PX4 does, the client code that breaks it and
    the fix, references), as ``fuzzoff rule CODE``; without a code, every rule in one line."""
    from fuzzoff.catalog import get_rule, load_catalog, render_page

    if not code:
        return "\n".join(
            f"{r.code} {r.name} ({r.severity.label}; {r.profiles_short()})"
            for r in load_catalog().values()
        )
    try:
        return render_page(get_rule(code.strip().upper()))
    except KeyError:
        raise ConfigError(f"unknown rule {code!r}: fuzzoff rule lists them") from None


def profiles_tool() -> dict[str, Any]:
    """The PX4 profiles modelled (each with the releases it covers) and the vehicle types."""
    from fuzzoff.profiles import VEHICLE_NOTES, VEHICLE_TYPES, px4_notes

    return {
        "px4": [{"profile": p, "covers": covers} for p, covers in px4_notes().items()],
        "vehicles": [{"type": v, "name": VEHICLE_NOTES[v]} for v in VEHICLE_TYPES],
    }


def server() -> Any:
    """The MCP server with the four tools, each marked read-only and closed-world."""
    try:
        from mcp.server import MCPServer
        from mcp.types import ToolAnnotations
    except ImportError:
        raise ConfigError("fuzzoff mcp needs the MCP SDK: pip install 'fuzzoff[mcp]'") from None
    from fuzzoff import __version__

    app = MCPServer("fuzzoff", instructions=INSTRUCTIONS, version=__version__)
    readonly = ToolAnnotations(read_only_hint=True, open_world_hint=False, idempotent_hint=True)
    app.tool(name="lint", annotations=readonly)(lint_tool)
    app.tool(name="gate", annotations=readonly)(gate_tool)
    app.tool(name="rule", annotations=readonly)(rule_tool)
    app.tool(name="profiles", annotations=readonly)(profiles_tool)
    return app


def run(args: argparse.Namespace) -> int:
    server().run("stdio")
    return 0
