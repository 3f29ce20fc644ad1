"""``fuzzoff profiles``: the PX4 versions and vehicle types the gate model and rules know."""

from __future__ import annotations

import argparse
import json
from typing import Any

from rich.console import Console
from rich.table import Table

from fuzzoff.commands import add_command
from fuzzoff.commands._common import render_rich, write_output
from fuzzoff.profiles import VEHICLE_NOTES, VEHICLE_TYPES, px4_notes, px4_seen_running


def add_parser(sub: Any) -> None:
    parser = add_command(sub, "profiles")
    parser.add_argument("--format", choices=("terminal", "json"), default="terminal")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    seen = px4_seen_running()
    if args.format == "json":
        data = {
            "px4": [
                {"profile": p, "covers": covers, "seen_running": list(seen[p])}
                for p, covers in px4_notes().items()
            ],
            "vehicles": [{"type": v, "name": VEHICLE_NOTES[v]} for v in VEHICLE_TYPES],
        }
        write_output(json.dumps(data, indent=2) + "\n", None)
        return 0
    render_rich(_draw)
    return 0


def _draw(console: Console) -> None:
    from fuzzoff.report.terminal import table_box

    table = Table(title="PX4 profiles", show_edge=False, box=table_box(console))
    table.add_column("profile")
    table.add_column("covers")
    table.add_column("checked live (PX4 SITL)")
    seen = px4_seen_running()
    for p, covers in px4_notes().items():
        table.add_row(p, covers, ", ".join(seen[p]) or "no: from the code only")
    console.print(table)
    vehicles = Table(title="vehicle types", show_edge=False, box=table_box(console))
    vehicles.add_column("type")
    vehicles.add_column("vehicle")
    for v in VEHICLE_TYPES:
        vehicles.add_row(v, VEHICLE_NOTES[v])
    console.print(vehicles)
