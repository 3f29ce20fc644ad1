"""Rule pages point somewhere a user can follow, and show client code that is right.

Every page cites PX4's docs (docs.px4.io, in English) by page and section, or PX4's source by file
and release tag; none names a file the user does not have or a site nobody publishes. The client
examples parse, and the px4_msgs fields they use exist in the release they are written for (the
bundled definitions the readers use). ``docs/rules/`` holds the pages as ``fuzzoff rule`` prints
them.
"""

from __future__ import annotations

import ast
import importlib.util
import re
import tomllib
from pathlib import Path
from types import ModuleType

import pytest

from fuzzoff import releases
from fuzzoff.catalog import Rule, load_catalog, render_page
from fuzzoff.formats import px4_msgs
from tests.helpers import ROOT, run_cli

RULES = list(load_catalog().values())
TOOL_RULES = {"OFB001", "OFB002", "OFB003", "OFB004"}
"""Rules about reading the recording: their references are this project's own docs."""

DOCS_VERSIONS = "|".join(
    f"v1\\.{minor}"
    for release in releases.RELEASES
    if release.docs_page
    for minor in release.minors
)
"""The docs' versioned folders: every 1.x a release record with a docs page covers."""
DOCS_PAGE = re.compile(
    rf"^https://docs\.px4\.io/(main|{DOCS_VERSIONS})/en/[a-z0-9_/]+\.html(#[\w-]+)?$"
)
SOURCE_FILE = re.compile(r"^https://github\.com/PX4/PX4-Autopilot/(blob|tree)/v1\.\d+\.\d+/\S+$")


@pytest.mark.parametrize("rule", RULES, ids=[r.code for r in RULES])
def test_references_are_px4_docs_in_english_or_px4_source_at_a_tag(rule: Rule) -> None:
    urls = [ref.url for ref in rule.references]
    if rule.code in TOOL_RULES:
        assert all((ROOT / url).is_file() for url in urls), urls
        return
    px4 = [u for u in urls if DOCS_PAGE.match(u) or SOURCE_FILE.match(u)]
    assert px4, f"{rule.code} cites neither PX4's docs nor PX4's source: {urls}"
    others = [u for u in urls if u not in px4]
    assert all(u.startswith("https://mavlink.io/en/messages/common.html#") for u in others), others
    assert all(ref.title for ref in rule.references)


@pytest.mark.parametrize("rule", RULES, ids=[r.code for r in RULES])
def test_page_names_no_private_file_no_made_up_site_and_no_translated_section(rule: Rule) -> None:
    page = render_page(rule, test_stream=True)
    for banned in ("seed", "gate spec", "fuzzoff.dev", "px4-offboard-gate", "rules.md)"):
        assert banned not in page.lower(), f"{rule.code}: {banned!r}"
    assert not re.search(r"\bD\d{1,2}\b", page), f"{rule.code} cites a docs-vs-code row by number"
    # section titles in English: no Cyrillic or CJK left from the translated pages
    assert not re.search(r"[\u0400-\u04ff\u3000-\u9fff\uff00-\uffef]", page), rule.code


@pytest.mark.parametrize("rule", RULES, ids=[r.code for r in RULES])
def test_page_shows_client_code_and_keeps_the_test_stream_behind_verbose(rule: Rule) -> None:
    assert rule.example is not None, f"rules/{rule.code}.toml has no [example]"
    assert rule.example.bad.strip() and rule.example.bad != rule.example.good
    page = render_page(rule)
    assert f"```{rule.example.language}\n{rule.example.bad}\n```" in page
    assert "## Use instead" in page
    assert "## Test stream" not in page and 'kind = "' not in page
    if rule.stream_bad:
        assert "## Test stream" in render_page(rule, test_stream=True)


def _parse_python(code: str) -> ast.Module:
    """The snippet as a module; top-level ``await`` allowed (MAVSDK examples)."""
    flags = ast.PyCF_ONLY_AST | ast.PyCF_ALLOW_TOP_LEVEL_AWAIT
    tree: ast.Module = compile(code, "<example>", "exec", flags=flags)
    return tree


def _python_field_uses(tree: ast.Module, messages: set[str]) -> list[tuple[str, str]]:
    """(message, field) for every keyword of a ``Message(...)`` call and every attribute of a
    name bound to one (``sp = TrajectorySetpoint()`` then ``sp.position = ...``)."""
    bound: dict[str, str] = {}
    uses: list[tuple[str, str]] = []
    for node in ast.walk(tree):
        call = isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
        if call and node.func.id in messages:
            uses += [(node.func.id, kw.arg) for kw in node.keywords if kw.arg]
        if (
            isinstance(node, ast.Assign)
            and isinstance(node.value, ast.Call)
            and isinstance(node.value.func, ast.Name)
            and node.value.func.id in messages
        ):
            for target in node.targets:
                if isinstance(target, ast.Name):
                    bound[target.id] = node.value.func.id
                elif isinstance(target, ast.Attribute):
                    bound[ast.unparse(target)] = node.value.func.id
    for node in ast.walk(tree):
        # an upper-case attribute is a constant, not a field
        if isinstance(node, ast.Attribute) and not node.attr.isupper():
            owner = ast.unparse(node.value)
            if owner in bound:
                uses.append((bound[owner], node.attr))
    return uses


_CPP_DECL = re.compile(r"(?:px4_msgs::msg::)?(\w+)\s+(\w+)\s*\{\s*\}")


def _cpp_field_uses(code: str, messages: set[str]) -> list[tuple[str, str]]:
    bound = {name: msg for msg, name in _CPP_DECL.findall(code) if msg in messages}
    return [(bound[v], f) for v, f in re.findall(r"\b(\w+)\.(\w+)\s*=", code) if v in bound]


def _fields(release: str) -> dict[str, set[str]]:
    folder = Path(px4_msgs.__file__).parent / release
    out = {}
    for path in folder.glob("*.msg"):
        names = set()
        for line in path.read_text(encoding="utf-8").splitlines():
            parts = line.split("#", 1)[0].split()
            if len(parts) >= 2 and "=" not in line:
                names.add(parts[1])
        out[path.stem] = names
    return out


EXAMPLES = [r for r in RULES if r.example is not None]


@pytest.mark.parametrize("rule", EXAMPLES, ids=[r.code for r in EXAMPLES])
def test_client_code_parses_and_uses_fields_its_px4_msgs_release_has(rule: Rule) -> None:
    ex = rule.example
    assert ex is not None
    fields = _fields(ex.px4)
    for code in (ex.bad, ex.good):
        if ex.language == "python":
            uses = _python_field_uses(_parse_python(code), set(fields))
        elif ex.language == "cpp":
            uses = _cpp_field_uses(code, set(fields))
        elif ex.language == "toml":
            tomllib.loads(code)
            uses = []
        else:
            uses = []
        wrong = [(msg, f) for msg, f in uses if f not in fields[msg]]
        assert not wrong, f"{rule.code}: px4_msgs {ex.px4} has no {wrong}"


def test_the_field_check_catches_a_field_from_another_release() -> None:
    """The check above can fail: ``actuator`` is 1.14's field, ``direct_actuator`` 1.15's."""
    tree = _parse_python("ocm = OffboardControlMode(actuator=True)\nocm.position = True\n")
    fields = _fields("1.15")
    uses = _python_field_uses(tree, set(fields))
    assert ("OffboardControlMode", "actuator") in uses
    assert "actuator" not in fields["OffboardControlMode"]
    assert "actuator" in _fields("1.14")["OffboardControlMode"]
    cpp = _cpp_field_uses(
        "px4_msgs::msg::OffboardControlMode m{};\nm.actuator = true;", {"OffboardControlMode"}
    )
    assert cpp == [("OffboardControlMode", "actuator")]


def test_docs_rules_holds_every_page_as_fuzzoff_rule_prints_it() -> None:
    """``docs/rules/CODE.md`` is what reports point at: regenerate with docs/rules/build.py."""
    folder = ROOT / "docs" / "rules"
    for rule in RULES:
        page = folder / f"{rule.code}.md"
        assert page.read_text(encoding="utf-8") == render_page(rule), (
            f"{page} is stale: run .venv/bin/python docs/rules/build.py"
        )
        assert rule.page == f"docs/rules/{rule.code}.md"
    listed = {p.stem for p in folder.glob("OFB*.md")}
    assert listed == {r.code for r in RULES}


def test_rule_verbose_shows_the_test_stream() -> None:
    plain = run_cli(["rule", "OFB101"])
    verbose = run_cli(["rule", "OFB101", "--verbose"])
    assert plain.returncode == verbose.returncode == 0
    assert "## Use instead" in plain.stdout and "Test stream" not in plain.stdout
    assert "## Test stream" in verbose.stdout and 'kind = "control_mode"' in verbose.stdout


def _build() -> ModuleType:
    spec = importlib.util.spec_from_file_location(
        "rules_build", ROOT / "docs" / "rules" / "build.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_overview_pages_list_the_rules_as_the_catalog_has_them() -> None:
    """docs/rules.md and docs/rules-rover-mavlink.md repeat no rule fact by hand: their tables
    (names, severities and when each is given, profiles, option defaults) are the build's."""
    for path, text in _build().overview_pages().items():
        assert path.read_text(encoding="utf-8") == text, (
            f"{path.name} is stale: run .venv/bin/python docs/rules/build.py"
        )
    rules_md = (ROOT / "docs" / "rules.md").read_text(encoding="utf-8")
    for rule in RULES:
        for option in rule.options:
            assert f"| `{rule.code}.{option.name}` | `{option.default}` |" in rules_md
        for level, when in rule.severities:
            assert when in rules_md, (rule.code, level)
    mavlink_md = (ROOT / "docs" / "rules-rover-mavlink.md").read_text(encoding="utf-8")
    ofb507 = (
        "| [OFB507](rules/OFB507.md) | rover-attitude-target-unsupported | error (or warning) |"
    )
    assert ofb507 in mavlink_md


def test_an_overview_page_without_its_table_s_place_is_refused() -> None:
    build = _build()
    with pytest.raises(SystemExit, match="catalog:options"):
        build.fill(
            "# rules\n<!-- catalog:severities -->\n<!-- catalog:end -->\n",
            build.TABLES["rules.md"],
            RULES,
        )
