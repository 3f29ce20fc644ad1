"""``fuzzoff rule [CODE]``: a rule's page, or every rule one line each."""

from __future__ import annotations

import argparse
import json
from typing import Any

from rich.console import Console
from rich.markdown import Markdown
from rich.table import Table

from fuzzoff.catalog import Rule, get_rule, load_catalog, render_page
from fuzzoff.commands import add_command
from fuzzoff.config import ConfigError


def add_parser(sub: Any) -> None:
    parser = add_command(sub, "rule")
    parser.add_argument("code", nargs="?", help="a rule code such as OFB101")
    parser.add_argument("--format", choices=("terminal", "json", "markdown"), default="terminal")
    parser.set_defaults(run=run)


def rule_json(rule: Rule) -> dict[str, Any]:
    return {
        "code": rule.code,
        "name": rule.name,
        "severity": rule.severity.label,
        "profiles": {"px4": list(rule.px4), "vehicles": list(rule.vehicles)},
        "source": {"doc": rule.source_doc, "section": rule.source_section},
        "summary": rule.summary,
        "why": rule.why,
        "docs_vs_code": rule.docs_vs_code or None,
        "heuristic": rule.heuristic,
        "options": {o.name: {"default": o.default, "doc": o.doc} for o in rule.options},
        "url": rule.url,
    }


def run(args: argparse.Namespace) -> int:
    console = Console(highlight=False)
    if args.code:
        try:
            rule = get_rule(args.code)
        except KeyError:
            raise ConfigError(f"unknown rule {args.code!r} (fuzzoff rule lists them)") from None
        if args.format == "json":
            print(json.dumps(rule_json(rule), indent=2, ensure_ascii=False))
        elif args.format == "markdown" or not console.is_terminal:
            print(render_page(rule), end="")
        else:
            console.print(Markdown(render_page(rule)))
        return 0
    rules = list(load_catalog().values())
    if args.format == "json":
        print(json.dumps([rule_json(r) for r in rules], indent=2, ensure_ascii=False))
        return 0
    table = Table(show_edge=False)
    for column in ("code", "name", "severity", "profiles"):
        table.add_column(column)
    for r in rules:
        table.add_row(r.code, r.name, r.severity.label, r.profiles_text())
    console.print(table)
    return 0
