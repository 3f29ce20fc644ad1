"""One module per ``fuzzoff`` subcommand (``add_parser`` + ``run``), imported by ``cli``.

``SUMMARIES`` is the list of subcommands and their one-line help, kept here so that
``fuzzoff --help`` can show them without importing every command (``fuzz`` pulls in
Hypothesis: about 0.25 s).
"""

from __future__ import annotations

import argparse
from typing import Any

SUMMARIES: dict[str, str] = {
    "fleet": "a page over a fleet's Parquet dataset: rules per week, release, vehicle",
    "fuzz": "search setpoint streams for hazards the rules miss (seeded, shrunk)",
    "gate": "the gate model's timeline for a recording, beside the recorded mode",
    "lint": "lint recordings (tlog, ULog, MCAP, ROS 2 and ROS 1 bags)",
    "mcp": "serve lint, gate, rule and profiles to a coding assistant (MCP over stdio)",
    "profiles": "list the modelled PX4 versions and vehicle types",
    "replay": "re-check a fuzz reproducer, or replay it to a live PX4 (--to udp:HOST:14580)",
    "rule": "show a rule's documentation, or list all rules",
    "sitl": "run a scenario or replay a recording on a real PX4 SITL, beside the gate model",
}


def add_command(sub: Any, name: str) -> argparse.ArgumentParser:
    """The subcommand's parser, with its summary as help."""
    parser: argparse.ArgumentParser = sub.add_parser(name, help=SUMMARIES[name])
    return parser
