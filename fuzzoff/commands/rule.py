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
from fuzzoff.commands._common import render_rich, write_output
from fuzzoff.config import ConfigError


def add_parser(sub: Any) -> None:
    parser = add_command(sub, "rule")
    parser.add_argument("code", nargs="?", help="a rule code such as OFB101")
    parser.add_argument("--format", choices=("terminal", "json", "markdown"), default="terminal")
    parser.add_argument(
        "--verbose",
        "-v",
        action="store_true",
        help="also show the test stream: the events the tests replay through the rule",
    )
    parser.set_defaults(run=run)


def rule_json(rule: Rule) -> dict[str, Any]:
    return {
        "code": rule.code,
        "name": rule.name,
        "severity": rule.severity.label,
        "profiles": {"px4": list(rule.px4), "vehicles": list(rule.vehicles)},
        "summary": rule.summary,
        "why": rule.why,
        "docs_vs_code": rule.docs_vs_code or None,
        "heuristic": rule.heuristic,
        "options": {o.name: {"default": o.default, "doc": o.doc} for o in rule.options},
        "example": None
        if rule.example is None
        else {
            "client": rule.example.client,
            "language": rule.example.language,
            "bad": rule.example.bad,
            "good": rule.example.good,
        },
        "references": [{"title": r.title, "url": r.url} for r in rule.references],
        "page": rule.page,
    }


def run(args: argparse.Namespace) -> int:
    if args.code:
        try:
            rule = get_rule(args.code)
        except KeyError:
            raise ConfigError(f"unknown rule {args.code!r} (fuzzoff rule lists them)") from None
        if args.format == "json":
            write_output(json.dumps(rule_json(rule), indent=2, ensure_ascii=False) + "\n", None)
        elif args.format == "markdown":
            write_output(render_page(rule, test_stream=args.verbose), None)
        else:
            render_rich(lambda console: _draw_page(console, rule, args.verbose))
        return 0
    rules = list(load_catalog().values())
    if args.format == "json":
        text = json.dumps([rule_json(r) for r in rules], indent=2, ensure_ascii=False)
        write_output(text + "\n", None)
    elif args.format == "markdown":
        write_output("\n".join(render_page(r, test_stream=args.verbose) for r in rules), None)
    else:
        render_rich(lambda console: _draw_list(console, rules))
    return 0


def _draw_page(console: Console, rule: Rule, verbose: bool) -> None:
    """Rendered Markdown on a terminal; the Markdown itself in a file or a pipe."""
    page = render_page(rule, test_stream=verbose)
    if console.is_terminal:
        console.print(Markdown(page))
    else:
        console.out(page, end="", highlight=False)


def _draw_list(console: Console, rules: list[Rule]) -> None:
    from fuzzoff.report.terminal import table_box

    table = Table(show_edge=False, box=table_box(console))
    # code, name and severity are never broken (a name cut mid-word reads as two); the
    # profiles wrap between words, and fit beside the longest name in 80 columns
    for column in ("code", "name", "severity"):
        table.add_column(column, no_wrap=True)
    table.add_column("profiles", overflow="fold")
    for r in rules:
        table.add_row(r.code, r.name, r.severity.label, r.profiles_short())
    console.print(table)
