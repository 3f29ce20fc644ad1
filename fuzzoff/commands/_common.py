"""Options shared by the commands that judge recordings, and how they become ``Settings``."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from fuzzoff.config import ConfigError, Settings, load_settings
from fuzzoff.report import FORMATS


def add_profile_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--px4", metavar="VERSION", help="PX4 release (1.15.4) or profile (legacy, main)"
    )
    parser.add_argument("--vehicle", metavar="TYPE", help="mc, fw, vtol, rover-ackermann, ...")
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="override a PX4 parameter for the gate model (repeatable), e.g. COM_OF_LOSS_T=0.5",
    )


def add_rule_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--select", metavar="CODES", help="comma-separated codes or prefixes (OFB1)"
    )
    parser.add_argument("--extend-select", metavar="CODES", help="add to the selected rules")
    parser.add_argument("--ignore", metavar="CODES", help="comma-separated codes or prefixes")
    parser.add_argument(
        "--fail-on",
        choices=("error", "warning", "info"),
        help="lowest severity that makes the exit status 1 (default warning)",
    )


def add_output_options(parser: argparse.ArgumentParser, formats: tuple[str, ...] = FORMATS) -> None:
    parser.add_argument("--format", choices=formats, default="terminal")
    parser.add_argument("--output", "-o", metavar="FILE", help="write the report here")


def parse_params(values: list[str]) -> dict[str, float]:
    params: dict[str, float] = {}
    for item in values:
        name, sep, value = item.partition("=")
        try:
            number = float(value)
            if not sep or not math.isfinite(number):
                raise ValueError
            params[name.strip().upper()] = number
        except ValueError:
            raise ConfigError(f"--param {item!r}: expected NAME=NUMBER (a finite number)") from None
    return params


def settings_from_args(args: argparse.Namespace) -> Settings:
    overrides: dict[str, Any] = {
        "px4": getattr(args, "px4", None),
        "vehicle": getattr(args, "vehicle", None),
        "select": getattr(args, "select", None),
        "extend-select": getattr(args, "extend_select", None),
        "ignore": getattr(args, "ignore", None),
        "fail-on": getattr(args, "fail_on", None),
    }
    params = parse_params(getattr(args, "param", []) or [])
    if params:
        overrides["params"] = params
    return load_settings(Path.cwd(), overrides)


def write_output(text: str, output: str | None) -> None:
    if output is None:
        sys.stdout.write(text)
        return
    path = Path(output)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise ConfigError(f"cannot write {output}: {exc.strerror or exc}") from None
