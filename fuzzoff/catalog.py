"""The rule catalog: one TOML file per rule in ``rules/``, documented the way ruff documents rules.

A rule file holds ``code``, ``name``, ``severity``, ``profiles``, ``summary`` (what it does),
``why`` (why it is bad), ``docs_vs_code`` (where PX4's code behaves differently), ``options``
(thresholds with defaults), ``example`` (the client code that breaks the rule and its fix, in the
client that fits: rclpy or rclcpp with px4_msgs, MAVSDK, MAVROS, pymavlink), ``test_stream.bad`` /
``test_stream.good`` (tiny event streams the tests replay through the rule), ``references``
(PX4's docs by page and section, PX4's source by file and release tag), ``severities`` (for a
rule whose findings take several severities: when each is given; ``severity`` is the highest),
and what fuzz campaigns need to know: ``explains`` (the outcomes of the gate model,
``HAZARD_KINDS``, that a finding of the rule explains) and ``reports`` (those of them the rule
reports itself: when the recording cannot show them, OFB002 says so and a warning of an
explaining rule is enough), and ``sent_stream`` (the rule judges the keep-alive and setpoint
stream as the companion sent it: it is not run on a recording that does not hold that stream,
and OFB002 names it there).

Each page is also a Markdown file in the repository, ``docs/rules/CODE.md``, written from the
catalog by ``docs/rules/build.py`` (a test keeps the two equal): that is where a rule links to.
"""

from __future__ import annotations

import functools
import json
import os
import zlib
from collections.abc import Iterable
from dataclasses import field
from pathlib import Path
from typing import Any, Literal, get_args

from fuzzoff import releases
from fuzzoff._version import __version__
from fuzzoff.findings import Severity
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import VEHICLE_TYPES, seen_running_text

PROJECT_URL = "https://github.com/fuzzoff/fuzzoff"
"""The project's home: its public repository. A placeholder until the repository's address is
decided; every address of the project in a report (SARIF's ``informationUri`` and each rule's
``helpUri``) is derived from it, so that confirming it is a one-line change."""

RULE_PAGE = "docs/rules/{code}.md"
"""Where a rule's page sits in the repository, relative to its root. The project publishes no web
site, so reports link here (the HTML report carries the pages themselves)."""

PAGE_BRANCH = "main"
"""The branch whose copy of a rule page ``Rule.page_url`` names."""

REFERENCE_PREFIXES = (
    "https://docs.px4.io/",
    "https://github.com/PX4/PX4-Autopilot/",
    "https://mavlink.io/en/",
    "docs/",
)
"""What a reference may point at: PX4's docs, PX4's source at a release tag, the MAVLink message
definitions, or this repository's own docs (for the rules about reading a recording)."""

EXAMPLE_LANGUAGES = ("python", "cpp", "sh", "toml")

HazardKind = Literal[
    "request_rejected", "arm_rejected", "failsafe", "disarmed", "setpoint_dropped", "controller"
]
"""An outcome the gate model predicts that a stream did not intend (``fuzz.hazards``)."""
HAZARD_KINDS: tuple[HazardKind, ...] = get_args(HazardKind)


class CatalogError(ValueError):
    """A rule file is malformed (a bug in the catalog, caught by the tests)."""


@dataclass(frozen=True, slots=True)
class RuleOption:
    name: str
    default: float | int | str | bool
    doc: str


@dataclass(frozen=True, slots=True)
class Reference:
    """A page and section of PX4's docs, a file of PX4's source at a release tag, or a page of
    this repository's docs (a path relative to its root)."""

    title: str
    url: str

    @property
    def external(self) -> bool:
        return self.url.startswith("https://")

    def markdown(self) -> str:
        return f"[{self.title}]({self.url})" if self.external else f"{self.title}: `{self.url}`"


@dataclass(frozen=True, slots=True)
class ClientExample:
    """The code a user writes that breaks the rule (``bad``) and its fix (``good``)."""

    client: str
    """The client library, and the PX4 release the code is written for."""
    language: str
    bad: str
    good: str
    px4: str = "1.15"
    """The px4_msgs release whose fields the code uses (ROS 2 clients)."""


@dataclass(frozen=True, slots=True)
class Rule:
    code: str
    name: str
    severity: Severity
    summary: str
    why: str
    px4: tuple[str, ...]
    vehicles: tuple[str, ...]
    references: tuple[Reference, ...]
    docs_vs_code: str = ""
    heuristic: bool = False
    options: tuple[RuleOption, ...] = ()
    example: ClientExample | None = None
    stream_bad: tuple[dict[str, Any], ...] = ()
    """The test stream: events the tests replay through the rule (it must report them)."""
    stream_good: tuple[dict[str, Any], ...] = ()
    """The test stream the rule must stay silent on."""
    stream_profile: dict[str, str] = field(default_factory=dict)
    formats: tuple[str, ...] = ()
    """Recording formats whose data can show this rule (empty = all)."""
    severities: tuple[tuple[Severity, str], ...] = ()
    """When a finding takes each severity, highest first, for a rule whose findings take several
    (or whose one severity needs saying when); empty: always ``severity``."""
    explains: tuple[HazardKind, ...] = ()
    """The gate outcomes a finding of this rule explains (fuzz campaigns' ``explained``)."""
    reports: tuple[HazardKind, ...] = ()
    """The outcomes among ``explains`` this rule reports itself, not only a cause of."""
    sent_stream: bool = False
    """The rule judges the stream as sent: off where the recording does not hold it."""

    @property
    def page(self) -> str:
        """The rule's page in the repository, relative to its root."""
        return RULE_PAGE.format(code=self.code)

    @property
    def page_url(self) -> str:
        """The rule's page in the project's repository, as an absolute address."""
        return f"{PROJECT_URL}/blob/{PAGE_BRANCH}/{self.page}"

    def applies_to(self, px4: str, vehicle: str) -> bool:
        return px4 in self.px4 and vehicle in self.vehicles

    def option(self, name: str) -> RuleOption:
        for opt in self.options:
            if opt.name == name:
                return opt
        raise KeyError(f"{self.code} has no option {name!r}")

    def profiles_text(self) -> str:
        px4 = "all" if self.px4 == releases.names() else ", ".join(self.px4)
        veh = "all" if self.vehicles == VEHICLE_TYPES else ", ".join(self.vehicles)
        return f"PX4 {px4}; vehicles {veh}"

    def profiles_short(self) -> str:
        """``profiles_text`` for a table row: a run of profiles up to the newest as ``1.13+``
        (as the rule pages' front matter writes it)."""
        names = releases.names()
        px4 = ", ".join(self.px4)
        if self.px4 == names:
            px4 = "all"
        elif self.px4 and self.px4 == names[names.index(self.px4[0]) :]:
            px4 = f"{self.px4[0]}+"
        rovers = tuple(v for v in VEHICLE_TYPES if v.startswith("rover"))
        veh = ", ".join(self.vehicles)
        if self.vehicles == VEHICLE_TYPES:
            return f"PX4 {px4}"
        if self.vehicles == rovers:
            veh = "rovers"
        return f"PX4 {px4}; {veh}"


def _catalog_dir() -> Path:
    """``rules/`` beside the package in a checkout, or ``fuzzoff/_catalog`` in a wheel. Found
    from ``__file__``, as ``importlib.resources.files`` would for a package on disk, without
    importing ``importlib.resources`` (and through it zipfile and tempfile) on every start."""
    packaged = Path(__file__).resolve().parent / "_catalog"
    if packaged.is_dir():
        return packaged
    return Path(__file__).resolve().parent.parent / "rules"


def _expand(
    values: Iterable[str], universe: tuple[str, ...], what: str, path: Path
) -> tuple[str, ...]:
    chosen: set[str] = set()
    for value in values:
        if value == "all":
            chosen.update(universe)
        elif value.endswith("+") and value[:-1] in universe:
            chosen.update(universe[universe.index(value[:-1]) :])
        elif value in universe:
            chosen.add(value)
        elif value == "rover":
            chosen.update(v for v in universe if v.startswith("rover"))
        else:
            raise CatalogError(f"{path.name}: unknown {what} {value!r}")
    return tuple(v for v in universe if v in chosen)


def cache_file(directory: Path) -> Path | None:
    """Where the JSON copy of the pages in ``directory`` is kept: the user's cache folder (as
    black and pip keep theirs), one file per catalog folder, never inside an installed package.

    Every fuzzoff process needs the whole catalog: parsing 48 TOML pages costs about 25 ms, the
    copy about 7 ms. None when there is no home folder to keep it in."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    if not os.path.isabs(base):
        return None  # "~" not expanded: no home folder
    folder = zlib.crc32(str(directory.resolve()).encode("utf-8", "surrogateescape"))
    return Path(base, "fuzzoff", f"catalog-{folder:08x}.json")


def _pages(directory: Path, cache: Path | None) -> dict[str, dict[str, Any]]:
    """Every rule page's data by file name: from the JSON copy ``cache`` while it was made from
    these very pages (names, sizes and modification times, and this fuzzoff's version), else
    parsed and the copy written again. A copy that cannot be read or written (no home folder, a
    read-only one) only costs the parse."""
    paths = sorted(directory.glob("OFB*.toml"))
    stats = [(path.name, path.stat()) for path in paths]
    key = [__version__, *([name, st.st_size, st.st_mtime_ns] for name, st in stats)]
    if cache is not None:
        try:
            cached = json.loads(cache.read_bytes())
            if cached["key"] == key:
                pages: dict[str, dict[str, Any]] = cached["pages"]
                return pages
        except (OSError, ValueError, KeyError, TypeError):
            pass
    import tomllib  # only when the JSON copy is stale: most runs never parse a page

    pages = {}
    for path in paths:
        with path.open("rb") as fh:
            pages[path.name] = tomllib.load(fh)
    if cache is not None:
        _write(cache, {"key": key, "pages": pages})
    return pages


def _write(cache: Path, data: dict[str, Any]) -> None:
    """Replace ``cache`` at once (a concurrent reader sees the old copy or the new one)."""
    import tempfile  # only when the copy is written again

    try:
        text = json.dumps(data)
        cache.parent.mkdir(parents=True, exist_ok=True)
        fd, temp = tempfile.mkstemp(dir=cache.parent, prefix=".catalog-", suffix=".json")
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                fh.write(text)
            os.replace(temp, cache)
        except BaseException:
            os.unlink(temp)
            raise
    except (OSError, TypeError, ValueError):
        pass  # no copy this time: the next process parses the pages again


def _load_rule(path: Path, data: dict[str, Any]) -> Rule:
    try:
        profiles = data.get("profiles", {})
        options = tuple(
            RuleOption(name=name, default=opt["default"], doc=opt["doc"])
            for name, opt in data.get("options", {}).items()
        )
        references = tuple(Reference(r["title"], r["url"]) for r in data["references"])
        example = data.get("example")
        stream = data.get("test_stream", {})
        rule = Rule(
            code=data["code"],
            name=data["name"],
            severity=Severity.parse(data["severity"]),
            summary=data["summary"].strip(),
            why=data["why"].strip(),
            px4=_expand(profiles.get("px4", ["all"]), releases.names(), "PX4 profile", path),
            vehicles=_expand(profiles.get("vehicles", ["all"]), VEHICLE_TYPES, "vehicle", path),
            references=references,
            docs_vs_code=data.get("docs_vs_code", "").strip(),
            heuristic=bool(data.get("heuristic", False)),
            options=options,
            example=None if example is None else _client_example(example),
            stream_bad=tuple(stream.get("bad", ())),
            stream_good=tuple(stream.get("good", ())),
            stream_profile=dict(stream.get("profile", {})),
            formats=tuple(data.get("formats", ())),
            severities=_severities(data.get("severities", {}), path),
            explains=_kinds(data.get("explains", ()), "explains", path),
            reports=_kinds(data.get("reports", ()), "reports", path),
            sent_stream=bool(data.get("sent_stream", False)),
        )
    except KeyError as exc:
        raise CatalogError(f"{path.name}: missing key {exc}") from None
    if rule.code != path.stem:
        raise CatalogError(f"{path.name}: code {rule.code} does not match the file name")
    if not rule.references:
        raise CatalogError(f"{path.name}: no references")
    for ref in rule.references:
        if not ref.url.startswith(REFERENCE_PREFIXES):
            raise CatalogError(f"{path.name}: reference {ref.url!r} is not PX4's docs or source")
    if rule.example is not None and rule.example.language not in EXAMPLE_LANGUAGES:
        raise CatalogError(f"{path.name}: example language {rule.example.language!r}")
    if rule.severities and rule.severities[0][0] is not rule.severity:
        raise CatalogError(f"{path.name}: severity is not the highest of its severities")
    if not set(rule.reports) <= set(rule.explains):
        raise CatalogError(f"{path.name}: reports outcomes it does not explain")
    return rule


def _severities(data: dict[str, str], path: Path) -> tuple[tuple[Severity, str], ...]:
    try:
        levels = [(Severity.parse(level), str(when).strip()) for level, when in data.items()]
    except ValueError as exc:
        raise CatalogError(f"{path.name}: severities: {exc}") from None
    return tuple(sorted(levels, key=lambda item: item[0], reverse=True))


def _kinds(values: Iterable[str], key: str, path: Path) -> tuple[HazardKind, ...]:
    """``values`` as hazard kinds, in ``HAZARD_KINDS`` order."""
    chosen = set(values)
    unknown = chosen - set(HAZARD_KINDS)
    if unknown:
        raise CatalogError(f"{path.name}: {key}: unknown outcome {sorted(unknown)[0]!r}")
    return tuple(kind for kind in HAZARD_KINDS if kind in chosen)


def _client_example(data: dict[str, Any]) -> ClientExample:
    return ClientExample(
        client=data["client"],
        language=data["language"],
        bad=data["bad"].strip("\n"),
        good=data["good"].strip("\n"),
        px4=data.get("px4", "1.15"),
    )


@functools.cache
def load_catalog() -> dict[str, Rule]:
    """All rules by code, sorted by code."""
    directory = _catalog_dir()
    return read_catalog(directory, cache_file(directory))


def read_catalog(directory: Path, cache: Path | None = None) -> dict[str, Rule]:
    """The rules of the pages in ``directory``, by code, sorted by code (through the JSON copy
    ``cache`` where given)."""
    pages = _pages(directory, cache)
    rules = [_load_rule(directory / name, data) for name, data in sorted(pages.items())]
    return {r.code: r for r in rules}


@functools.cache
def sent_stream_rules() -> tuple[str, ...]:
    """The rules that judge the keep-alive and setpoint stream as sent (``sent_stream`` on their
    page), by code. On a recording that cannot hold that stream (``RecordingInfo.
    stream_recorded``) they are not run: its absence there says nothing about the sender, and
    the engine says so in one OFB002."""
    return tuple(code for code, rule in load_catalog().items() if rule.sent_stream)


def get_rule(code: str) -> Rule:
    catalog = load_catalog()
    try:
        return catalog[code.upper()]
    except KeyError:
        raise KeyError(f"unknown rule {code!r}") from None


def expand_selectors(selectors: Iterable[str]) -> set[str]:
    """Codes matching the selectors (a code, a prefix such as ``OFB1``, or ``ALL``).

    Raises ``ValueError`` naming a selector that matches no rule.
    """
    codes = list(load_catalog())
    chosen: set[str] = set()
    for raw in selectors:
        selector = raw.strip().upper()
        if not selector:
            continue
        if selector == "ALL":
            chosen.update(codes)
            continue
        matched = [c for c in codes if c.startswith(selector)]
        if not matched:
            raise ValueError(f"unknown rule selector {raw!r}: no rule code starts with it")
        chosen.update(matched)
    return chosen


def render_page(rule: Rule, *, test_stream: bool = False) -> str:
    """The rule's page in Markdown, with ruff's headings plus Profiles and Docs vs code;
    ``test_stream`` adds the event streams the tests replay (``fuzzoff rule CODE --verbose``)."""
    lines = [f"# {rule.name} ({rule.code})", ""]
    lines += [f"Default severity: {rule.severity.label}. Profiles: {rule.profiles_text()}."]
    if rule.heuristic:
        lines += ["", "This rule is a heuristic: its thresholds are listed under Options."]
    lines += ["", "## What it does", "", rule.summary, "", "## Why is this bad?", "", rule.why]
    if rule.docs_vs_code:
        lines += ["", "## Docs vs code", "", rule.docs_vs_code]
    if rule.example is not None:
        ex = rule.example
        lines += ["", "## Example", "", f"{ex.client}:", "", f"```{ex.language}", ex.bad, "```"]
        lines += ["", "## Use instead", "", f"```{ex.language}", ex.good, "```"]
    if rule.options:
        lines += ["", "## Options", ""]
        for opt in rule.options:
            lines.append(f"- `{rule.code}.{opt.name}` (default `{opt.default}`): {opt.doc}")
    lines += ["", "## Profiles", "", rule.profiles_text() + "."]
    lines += ["", seen_running_text(rule.px4) + "."]
    lines += ["", "## References", ""]
    lines += [f"- {ref.markdown()}" for ref in rule.references]
    if test_stream and rule.stream_bad:
        profile = ", ".join(f"{k} {v}" for k, v in rule.stream_profile.items())
        lines += ["", "## Test stream", ""]
        lines += [
            "The events the tests replay through the rule"
            + (f" (profile: {profile})" if profile else "")
            + ": it reports the first stream and stays silent on the second.",
            "",
            "```toml",
            "bad = [",
            *_example_lines(rule.stream_bad),
            "]",
            "good = [",
            *_example_lines(rule.stream_good),
            "]",
            "```",
        ]
    return "\n".join(lines) + "\n"


def _example_lines(stream: tuple[dict[str, Any], ...]) -> list[str]:
    out = []
    for event in stream:
        items = ", ".join(f"{k} = {_toml_value(v)}" for k, v in event.items())
        out.append(f"  {{ {items} }},")
    return out


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return str(value)
