"""Write one Markdown page per rule (``docs/rules/OFB101.md`` ...) and an index, from the catalog,
and the tables of ``docs/rules.md`` and ``docs/rules-rover-mavlink.md`` that list rules.

Run ``.venv/bin/python docs/rules/build.py`` after editing ``rules/*.toml``; a test fails while a
page or table differs from what this writes. These pages are where the reports point a reader
(the SARIF ``page`` property, the JUnit failure text, the HTML report's rule sections): the same
text as ``fuzzoff rule CODE``, readable in the repository. In the two overview pages, the text
between ``<!-- catalog:NAME -->`` and ``<!-- catalog:end -->`` is this script's; the rest is
written by hand.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

from fuzzoff.catalog import Rule, load_catalog, render_page
from fuzzoff.findings import Severity
from fuzzoff.profiles import VEHICLE_NOTES, VEHICLE_TYPES
from fuzzoff.releases import names as release_names

HERE = Path(__file__).resolve().parent
DOCS = HERE.parent


def index(rules: list[Rule]) -> str:
    lines = [
        "# Rules",
        "",
        "One page per rule, written from `rules/*.toml` by `docs/rules/build.py` (the same",
        "text as `fuzzoff rule CODE`). `docs/rules.md` describes the families and how severities",
        "are chosen.",
        "",
        "| code | name | severity | profiles |",
        "| --- | --- | --- | --- |",
    ]
    for r in rules:
        lines.append(
            f"| [{r.code}]({r.code}.md) | {r.name} | {r.severity.label} | {r.profiles_text()} |"
        )
    return "\n".join(lines) + "\n"


def pages() -> dict[str, str]:
    """File name -> text, for every page this folder should hold."""
    rules = list(load_catalog().values())
    out = {f"{r.code}.md": render_page(r) for r in rules}
    out["README.md"] = index(rules)
    return out


# -- the overview pages' tables -------------------------------------------------------------


def _px4_text(px4: tuple[str, ...]) -> str:
    """``all versions``, ``1.13+``, ``1.16-1.17`` or a list, in profile order."""
    profiles: tuple[str, ...] = release_names()
    if px4 == profiles:
        return "all versions"
    start = profiles.index(px4[0])
    if px4 == profiles[start : start + len(px4)]:
        if start + len(px4) == len(profiles):
            return f"{px4[0]}+"
        if len(px4) > 2:
            return f"{px4[0]}-{px4[-1]}"
    return " and ".join(px4)


VEHICLE_NAMES = {  # plural where the table reads better so; else ``VEHICLE_NOTES``
    "mc": "multicopter",
    "fw": "fixed-wing",
    "vtol": "VTOL",
    "rover-ackermann": "Ackermann rovers",
    "rover-differential": "differential rovers",
    "rover-mecanum": "mecanum rovers",
}
FORMAT_NAMES = {  # the family a format's recordings belong to; else the format's own name
    "mcap": "ROS 2",
    "rosbag2-sqlite3": "ROS 2",
    "rosbag2-mcap": "ROS 2",
    "rosbag1": "ROS 1",
    "tlog": "tlog",
    "ulog": "ULog",
}


def _vehicles_text(vehicles: tuple[str, ...]) -> str:
    if vehicles == VEHICLE_TYPES:
        return "all vehicles"
    rovers = tuple(v for v in VEHICLE_TYPES if v.startswith("rover"))
    if vehicles == rovers:
        return "rovers"
    return ", ".join(VEHICLE_NAMES.get(v) or VEHICLE_NOTES.get(v, v) for v in vehicles)


def applies_to(rule: Rule) -> str:
    """Vehicles, PX4 versions and recordings, as one cell: ``rovers, 1.16+, ROS 2``."""
    parts = [_vehicles_text(rule.vehicles), _px4_text(rule.px4)]
    formats = list(dict.fromkeys(FORMAT_NAMES.get(f, f) for f in rule.formats))
    if formats:
        parts.append(", ".join(formats) + " only")
    return ", ".join(parts)


def severity_text(rule: Rule) -> str:
    """The default severity, and the others the rule's findings may take."""
    others = [level.label for level, _ in rule.severities if level is not rule.severity]
    return rule.severity.label + (f" (or {' or '.join(others)})" if others else "")


def _link(rule: Rule) -> str:
    return f"[{rule.code}](rules/{rule.code}.md)"


def overview_table(rules: list[Rule]) -> str:
    lines = ["| code | name | severity | applies to |", "| --- | --- | --- | --- |"]
    for r in rules:
        lines.append(f"| {_link(r)} | {r.name} | {severity_text(r)} | {applies_to(r)} |")
    return "\n".join(lines)


def severities_table(rules: list[Rule]) -> str:
    levels = (Severity.ERROR, Severity.WARNING, Severity.INFO)
    lines = ["| rule | error | warning | info |", "| --- | --- | --- | --- |"]
    for r in rules:
        if r.severities:
            when = dict(r.severities)
            cells = [f"{_link(r)} {r.name}", *(when.get(level, "") for level in levels)]
            lines.append("|" + "|".join(f" {c} " if c else " " for c in cells) + "|")
    return "\n".join(lines)


def options_table(rules: list[Rule]) -> str:
    lines = ["| option | default | what it sets |", "| --- | --- | --- |"]
    for r in rules:
        for opt in r.options:
            lines.append(f"| `{r.code}.{opt.name}` | `{opt.default}` | {opt.doc} |")
    return "\n".join(lines)


def _family(*prefixes: str) -> Callable[[list[Rule]], str]:
    return lambda rules: overview_table([r for r in rules if r.code.startswith(prefixes)])


TABLES: dict[str, dict[str, Callable[[list[Rule]], str]]] = {
    "rules.md": {"severities": severities_table, "options": options_table},
    "rules-rover-mavlink.md": {"rules": _family("OFB5", "OFB6")},
}
"""Overview page -> table name -> what writes it."""

_BLOCK = re.compile(r"(<!-- catalog:(\w+) -->\n).*?(<!-- catalog:end -->)", re.S)


def fill(text: str, tables: dict[str, Callable[[list[Rule]], str]], rules: list[Rule]) -> str:
    """``text`` with each ``catalog:NAME`` block written again; every table must have one."""
    seen: set[str] = set()

    def table(match: re.Match[str]) -> str:
        name = match.group(2)
        seen.add(name)
        return match.group(1) + tables[name](rules) + "\n" + match.group(3)

    out = _BLOCK.sub(table, text)
    missing = set(tables) - seen
    if missing:
        raise SystemExit(f"no <!-- catalog:{sorted(missing)[0]} --> block to fill")
    return out


def overview_pages() -> dict[Path, str]:
    """Overview page -> its text with the tables as the catalog gives them."""
    rules = list(load_catalog().values())
    return {
        DOCS / name: fill((DOCS / name).read_text(encoding="utf-8"), tables, rules)
        for name, tables in TABLES.items()
    }


def main() -> None:
    wanted = pages()
    for stale in HERE.glob("*.md"):
        if stale.name not in wanted:
            stale.unlink()
    for name, text in wanted.items():
        (HERE / name).write_text(text, encoding="utf-8")
    for path, text in overview_pages().items():
        path.write_text(text, encoding="utf-8")
    print(f"wrote {len(wanted)} pages to {HERE} and the tables of {len(TABLES)} overview pages")


if __name__ == "__main__":
    main()
