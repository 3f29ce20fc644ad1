"""Settings: ``[tool.fuzzoff]`` of the nearest pyproject.toml or a fuzzoff.toml, then the CLI.

Keys (ruff-like): ``px4``, ``vehicle``, ``select``, ``extend-select``, ``ignore``, ``fail-on``,
``severity`` (table code -> level), ``options`` (table code -> table of thresholds),
``params`` (PX4 parameter overrides for the gate model), ``per-file-ignores`` (glob -> codes),
``suppressions`` (recording -> list of ``{ code, from, to, reason }``: findings kept in the
reports as suppressed, not failing the run).
An unknown key, code or option is a usage error, never ignored.

As in ruff, each recording is judged with the nearest configuration above it (a ``rover/``
folder may carry its own ``fuzzoff.toml``); the command line applies on top of every one. A
recording with no configuration above it takes the one found from the current folder.
"""

from __future__ import annotations

import functools
import math
import os
import re
import tomllib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from difflib import get_close_matches
from pathlib import Path
from typing import Any

from fuzzoff import releases
from fuzzoff.catalog import expand_selectors, get_rule, load_catalog
from fuzzoff.findings import Finding, Report, Severity
from fuzzoff.gate.params import GATE_PARAMS
from fuzzoff.profiles import (
    VEHICLE_TYPES,
    ProfileError,
    px4_profile_for,
    vehicle_type_for,
)
from fuzzoff.releases import PX4Profile


class ConfigError(ValueError):
    """A usage error in the configuration or the command line (exit status 2)."""


KNOWN_KEYS = {
    "px4",
    "vehicle",
    "select",
    "extend-select",
    "ignore",
    "fail-on",
    "severity",
    "options",
    "params",
    "per-file-ignores",
    "suppressions",
}

NEVER = "never"
"""``fail-on = "never"`` (``--fail-on never``, ``--exit-zero``): no finding fails the run."""

_RELEASE = re.compile(r"^v?(\d+)\.(\d+)(?:\.(\d+))?")


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """`` (did you mean X?)`` for the closest choice, or nothing."""
    close = get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return f" (did you mean {close[0]}?)" if close else ""


def user_px4_profile(text: str) -> tuple[PX4Profile, str | None]:
    """The profile for a PX4 version the user names, and a note when its name differs.

    A release that does not exist or is not modelled is an error, not a guess: ``2.0`` is no
    PX4 release and ``1.19`` would be judged by a model of 1.18. ``1.12`` is the ``1.13``
    profile, ``1.5``-``1.10`` ``legacy``: the note says so.
    """
    name = text.strip()
    known = releases.names()
    if name in known:
        return px4_profile_for(name), None
    match = _RELEASE.match(name)
    if match is None:
        raise ProfileError(
            f"unknown PX4 version {text!r}{did_you_mean(name, known)}: give a release "
            f"such as 1.15.4, or one of {', '.join(known)}"
        )
    release = (int(match.group(1)), int(match.group(2)))
    shown = f"{release[0]}.{release[1]}"
    newest, oldest = releases.newest_listed(), releases.oldest_listed()
    if release > newest:
        raise ProfileError(
            f"PX4 {text} is not modelled: the newest release modelled is "
            f"{newest[0]}.{newest[1]}; give --px4 {releases.RELEASES[-1].name} to judge with "
            "the newest profile"
        )
    if release < oldest:
        raise ProfileError(
            f"PX4 {text} is not modelled: the oldest release modelled is {oldest[0]}.{oldest[1]} "
            f"(profile {releases.RELEASES[0].name})"
        )
    profile = px4_profile_for(name)
    if profile == shown:
        return profile, None
    covers = releases.get(profile).covers
    return profile, f"PX4 {shown} is judged with profile {profile} ({covers})"


def user_vehicle_type(text: str) -> str:
    """A vehicle type the user names. ``rover`` alone is refused: the rover kinds take
    setpoints differently (gate.md#rover), and a guess would judge the wrong one."""
    if text.strip().lower() == "rover":
        rovers = ", ".join(v for v in VEHICLE_TYPES if v.startswith("rover"))
        raise ProfileError(f"vehicle type 'rover' names no rover kind: give one of {rovers}")
    try:
        return vehicle_type_for(text)
    except ProfileError:
        raise ProfileError(
            f"unknown vehicle type {text!r}{did_you_mean(text.strip().lower(), VEHICLE_TYPES)}:"
            f" one of {', '.join(VEHICLE_TYPES)}"
        ) from None


@dataclass(frozen=True, slots=True)
class FileIgnore:
    """One ``per-file-ignores`` entry: codes turned off in the recordings its glob matches.

    As in ruff, a pattern without a slash matches a recording's name in any folder; one with a
    slash matches its path relative to the configuration's folder (``*`` stays within a
    folder, ``**`` spans folders); a leading ``!`` turns off the codes everywhere the rest of
    the pattern does not match."""

    pattern: str
    folder: str
    codes: frozenset[str]

    def matches(self, recording: str | Path) -> bool:
        negated = self.pattern.startswith("!")
        pattern = self.pattern[1:] if negated else self.pattern
        path = Path(os.path.abspath(recording))
        if "/" not in pattern:
            hit = glob_regex(pattern).fullmatch(path.name) is not None
        else:
            try:
                relative = path.relative_to(os.path.abspath(self.folder)).as_posix()
            except ValueError:
                relative = path.as_posix()
            target = path.as_posix() if pattern.startswith("/") else relative
            hit = glob_regex(pattern.removeprefix("./")).fullmatch(target) is not None
        return hit != negated


@functools.lru_cache(maxsize=256)
def glob_regex(pattern: str) -> re.Pattern[str]:
    """A glob as a regular expression: ``*``/``?`` within one path part, ``**`` across parts,
    ``[...]`` classes (``[!...]`` negated) and ``{a,b}`` alternatives."""
    out: list[str] = []
    i, depth = 0, 0
    while i < len(pattern):
        c = pattern[i]
        if pattern.startswith("**/", i):
            out.append("(?:.*/)?")
            i += 3
            continue
        if pattern.startswith("**", i):
            out.append(".*")
            i += 2
            continue
        if c == "*":
            out.append("[^/]*")
        elif c == "?":
            out.append("[^/]")
        elif c == "[" and "]" in pattern[i + 2 :]:
            end = pattern.index("]", i + 2)
            body = pattern[i + 1 : end]
            if body.startswith("!"):
                body = "^" + body[1:]
            out.append("[" + body.replace("\\", "\\\\") + "]")
            i = end
        elif c == "{":
            out.append("(?:")
            depth += 1
        elif c == "}" and depth:
            out.append(")")
            depth -= 1
        elif c == "," and depth:
            out.append("|")
        else:
            out.append(re.escape(c))
        i += 1
    if depth:
        raise ValueError(f"unclosed {{ in {pattern!r}")
    return re.compile("".join(out))


@dataclass(frozen=True, slots=True)
class ConfigSuppression:
    """One ``suppressions`` entry: findings of ``codes`` in the recordings ``pattern`` names
    (as ``per-file-ignores`` patterns match), starting within ``from_s``..``to_s`` seconds
    (the whole recording when both are None), taken out of the findings that fail a run and
    reported as suppressed, with ``reason``."""

    pattern: str
    folder: str
    codes: frozenset[str]
    reason: str
    source: str
    """The configuration file that holds it."""
    from_s: float | None = None
    to_s: float | None = None

    def matches(self, recording: str | Path) -> bool:
        return FileIgnore(self.pattern, self.folder, self.codes).matches(recording)

    def covers(self, finding: Finding) -> bool:
        """Is ``finding`` one this entry suppresses? A window takes the findings that start in
        it; a whole-recording finding only an entry without a window."""
        if finding.code not in self.codes:
            return False
        if self.from_s is None and self.to_s is None:
            return True
        if finding.time_s is None:
            return False
        low = -math.inf if self.from_s is None else self.from_s
        high = math.inf if self.to_s is None else self.to_s
        return low <= finding.time_s <= high


@dataclass(frozen=True, slots=True)
class Discovery:
    """What a run needs to find each recording's settings: the command line's values, laid over
    the nearest configuration above the recording (``Settings.for_recording``)."""

    overrides: tuple[tuple[str, Any], ...]
    cache: dict[str, Settings] = field(default_factory=dict, compare=False, hash=False)


@dataclass(frozen=True, slots=True)
class Settings:
    """Everything that changes what a lint run reports."""

    px4: PX4Profile | None = None
    """Profile forced by the user (None = detect)."""
    vehicle: str | None = None
    select: frozenset[str] = frozenset()
    """Enabled codes (empty = every rule)."""
    ignore: frozenset[str] = frozenset()
    fail_on: Severity = Severity.WARNING
    severity: Mapping[str, Severity] = field(default_factory=dict)
    options: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    params: Mapping[str, float] = field(default_factory=dict)
    config_file: str | None = None
    per_file_ignores: tuple[FileIgnore, ...] = ()
    param_origins: Mapping[str, str] = field(default_factory=dict)
    """Parameter -> where its value was set: ``--param`` or the configuration file's path."""
    notes: tuple[str, ...] = ()
    """What the user should hear about their settings (``--px4 1.12`` is judged as ``1.13``)."""
    discovery: Discovery | None = None
    """Set for a command-line run: each recording then takes its nearest configuration."""
    exit_zero: bool = False
    """``--exit-zero`` or ``fail-on = "never"``: findings never make the exit status 1 (the
    reports still judge them at ``fail_on``); input that could not be read still gives 2."""
    suppressions: tuple[ConfigSuppression, ...] = ()

    def exit_status(self, report: Report) -> int:
        """The run's exit status: 0 passed, 1 findings at or above ``fail_on`` (never with
        ``exit_zero``), 2 input not read completely."""
        status = report.exit_status(self.fail_on)
        return 0 if status == 1 and self.exit_zero else status

    def enabled(self, code: str) -> bool:
        if code in self.ignore:
            return False
        return not self.select or code in self.select

    def option(self, code: str, name: str) -> Any:
        """A rule threshold: the user's value, else the catalog default."""
        value = self.options.get(code, {}).get(name)
        if value is not None:
            return value
        return get_rule(code).option(name).default

    def severity_of(self, code: str, default: Severity) -> Severity:
        return self.severity.get(code, default)

    def param_origin(self, name: str) -> str:
        """How a report words where a parameter set by the user came from."""
        origin = self.param_origins.get(name)
        if origin is None:
            return "set by the user"  # Settings(params=...) from the Python API
        if origin == "--param":
            return "set with --param"
        return f"set in {Path(origin).name}"

    def resolved_for(self, recording: str | Path) -> Settings:
        """``for_recording``, resolved once: a lint given these settings does not look for a
        configuration again (no ``discovery`` left to follow); the per-file ignores it applies
        again add nothing."""
        return replace(self.for_recording(recording), discovery=None)

    def for_recording(self, recording: str | Path) -> Settings:
        """The settings one recording is judged with: its nearest configuration (for a
        command-line run), the command line on top, then the ``per-file-ignores`` it matches."""
        settings = self
        if self.discovery is not None:
            settings = _nearest_settings(self, self.discovery, Path(recording))
        ignored = frozenset(
            code
            for rule in settings.per_file_ignores
            if rule.matches(recording)
            for code in rule.codes
        )
        if ignored - settings.ignore:
            settings = replace(settings, ignore=settings.ignore | ignored)
        mine = tuple(s for s in settings.suppressions if s.matches(recording))
        if mine != settings.suppressions:
            settings = replace(settings, suppressions=mine)
        return settings


def find_config(start: Path) -> Path | None:
    """The nearest fuzzoff.toml, or pyproject.toml with a ``[tool.fuzzoff]`` table.

    A pyproject.toml that cannot be read is an error, not skipped: it may hold the table, and
    a parent folder's settings would silently take its place."""
    for folder in [start, *start.parents]:
        candidate = folder / "fuzzoff.toml"
        if candidate.is_file():
            return candidate
        candidate = folder / "pyproject.toml"
        if candidate.is_file():
            tool = _load_toml(candidate).get("tool", {})
            if isinstance(tool, dict) and "fuzzoff" in tool:
                return candidate
    return None


def _load_toml(path: Path) -> dict[str, Any]:
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{path}: not UTF-8 text (byte {exc.start}), as TOML must be") from None
    except OSError as exc:
        raise ConfigError(f"{path}: cannot be read: {exc.strerror or exc}") from None


def read_config_table(path: Path) -> dict[str, Any]:
    data = _load_toml(path)
    if path.name == "pyproject.toml":
        table = data.get("tool", {}).get("fuzzoff", {})
        return dict(table) if isinstance(table, dict) else {}
    return data


def _table(value: Any, key: str, where: str) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise ConfigError(f"{where}: {key} must be a table, e.g. {key} = {{ ... }}")
    return value


def _text(value: Any, key: str, where: str, example: str) -> str:
    """A text value; a number is refused, not turned into text: TOML reads ``px4 = 1.10`` as
    the number 1.1, whose text would name another release."""
    if not isinstance(value, str):
        raise ConfigError(f'{where}: {key} must be text in quotes, e.g. {key} = "{example}"')
    return value


def _codes(values: Any, key: str, where: str) -> set[str]:
    if isinstance(values, str):
        values = [v for v in values.split(",")]
    if not isinstance(values, list) or not all(isinstance(v, str) for v in values):
        raise ConfigError(f"{where}: {key} must be a list of rule codes or prefixes")
    try:
        codes = expand_selectors(values)
    except ValueError as exc:
        raise ConfigError(f"{where}: {key}: {exc}") from None
    if key == "select" and not codes:
        # an empty selection would mean every rule: say so rather than guess
        raise ConfigError(f"{where}: select names no rule (give codes or prefixes, or ALL)")
    return codes


def _option_value(value: Any, default: Any, where: str) -> Any:
    """A rule option as the catalog types it: every numeric option is a threshold (a time, a
    distance, a count or a fraction), so it must be a finite number, not below zero; NaN would
    make every comparison false and silently drop the rule's findings."""
    numeric = isinstance(default, (int, float)) and not isinstance(default, bool)
    if not numeric:
        return value
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        raise ConfigError(f"{where} must be a number")
    if not math.isfinite(value) or value < 0:
        raise ConfigError(f"{where} must be a finite number, 0 or more (got {value})")
    if isinstance(default, int) and value != int(value):
        raise ConfigError(f"{where} must be a whole number (got {value})")
    return value


def _param_name(name: str, where: str) -> str:
    """A parameter the gate model reads, in PX4's upper case; a typo is an error, not a value
    that changes nothing."""
    upper = name.upper()
    if upper not in GATE_PARAMS:
        close = get_close_matches(upper, GATE_PARAMS, n=1)
        hint = f"did you mean {close[0]}? " if close else ""
        raise ConfigError(
            f"{where}: params: {name!r} is not a parameter the gate model reads ({hint}"
            f"it reads {', '.join(GATE_PARAMS)})"
        )
    return upper


def settings_from_table(
    table: Mapping[str, Any], where: str, base: Settings | None = None
) -> Settings:
    """Apply a ``[tool.fuzzoff]``-shaped table (or CLI values in the same shape) to ``base``.

    ``where`` names the file, or is ``command line`` (keys are then named as options)."""
    settings = base or Settings()
    unknown = sorted(set(table) - KNOWN_KEYS)
    if unknown:
        known = ", ".join(sorted(KNOWN_KEYS))
        raise ConfigError(
            f"{where}: unknown key {unknown[0]}{did_you_mean(unknown[0], KNOWN_KEYS)}"
            + (f" (and {', '.join(unknown[1:])})" if unknown[1:] else "")
            + f"; known: {known}"
        )
    cli = where == "command line"
    key = "px4"
    try:
        if table.get("px4") is not None:
            px4 = _text(table["px4"], "px4", where, "1.15")
            profile, note = user_px4_profile(px4)
            settings = replace(settings, px4=profile)
            if note:
                source = "--px4" if cli else f"{where}: px4"
                settings = replace(settings, notes=(*settings.notes, f"{source}: {note}"))
        key = "vehicle"
        if table.get("vehicle") is not None:
            vehicle = _text(table["vehicle"], "vehicle", where, "mc")
            settings = replace(settings, vehicle=user_vehicle_type(vehicle))
    except ProfileError as exc:
        raise ConfigError(f"{'--' + key if cli else where}: {exc}") from None
    if table.get("select") is not None:
        settings = replace(settings, select=frozenset(_codes(table["select"], "select", where)))
    if table.get("extend-select") is not None:
        extra = _codes(table["extend-select"], "extend-select", where)
        base_select = settings.select or frozenset(load_catalog())
        settings = replace(settings, select=frozenset(base_select | extra))
    if table.get("ignore") is not None:
        settings = replace(
            settings, ignore=frozenset(settings.ignore | _codes(table["ignore"], "ignore", where))
        )
    if table.get("fail-on") is not None:
        fail_on = _text(table["fail-on"], "fail-on", where, "warning")
        if fail_on.strip().lower() == NEVER:
            settings = replace(settings, exit_zero=True)
        else:
            try:
                settings = replace(settings, fail_on=Severity.parse(fail_on), exit_zero=False)
            except ValueError as exc:
                raise ConfigError(f"{where}: fail-on: {exc}, or never") from None
    if table.get("severity") is not None:
        levels = dict(settings.severity)
        for selector, level in _table(table["severity"], "severity", where).items():
            try:
                sev = Severity.parse(str(level))
            except ValueError as exc:
                at = f"--severity {selector}" if cli else f"{where}: severity.{selector}"
                raise ConfigError(f"{at}: {exc}") from None
            for code in _codes([selector], "severity", where):
                levels[code] = sev
        settings = replace(settings, severity=levels)
    if table.get("options") is not None:
        options = {k: dict(v) for k, v in settings.options.items()}
        for code, values in _table(table["options"], "options", where).items():
            try:
                rule = get_rule(code)
            except KeyError:
                codes = list(load_catalog())
                raise ConfigError(
                    f"{where}: options: unknown rule {code!r}{did_you_mean(code, codes)}"
                ) from None
            for name, value in _table(values, f"options.{code}", where).items():
                try:
                    default = rule.option(name).default
                except KeyError:
                    names = [o.name for o in rule.options]
                    raise ConfigError(
                        f"{where}: options.{code}: unknown option {name!r}"
                        f"{did_you_mean(name, names)} (known: {', '.join(names) or 'none'})"
                    ) from None
                options.setdefault(rule.code, {})[name] = _option_value(
                    value, default, f"{where}: options.{code}.{name}"
                )
        settings = replace(settings, options=options)
    if table.get("params") is not None:
        params = dict(settings.params)
        origins = dict(settings.param_origins)
        for name, value in _table(table["params"], "params", where).items():
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                raise ConfigError(f"{where}: params.{name} must be a number")
            if not math.isfinite(value):
                raise ConfigError(f"{where}: params.{name} must be a finite number")
            upper = _param_name(str(name), where)
            params[upper] = float(value)
            origins[upper] = "--param" if cli else where
        settings = replace(settings, params=params, param_origins=origins)
    if table.get("per-file-ignores") is not None:
        settings = replace(
            settings, per_file_ignores=(*settings.per_file_ignores, *_file_ignores(table, where))
        )
    if table.get("suppressions") is not None:
        if cli:
            raise ConfigError("suppressions are read from a configuration file only")
        settings = replace(
            settings, suppressions=(*settings.suppressions, *_suppressions(table, where))
        )
    return settings


_SUPPRESSION_KEYS = {"code", "from", "to", "reason"}
_SUPPRESSION_EXAMPLE = '[{ code = "OFB101", from = 12.0, to = 15.5, reason = "bench test" }]'


def _suppressions(table: Mapping[str, Any], where: str) -> list[ConfigSuppression]:
    """``suppressions = { "RECORDING" = [{ code, from, to, reason }, ...] }``: a recording's
    path relative to the file's folder (or a pattern, as ``per-file-ignores``); ``code`` a code
    or prefix; ``from`` and ``to`` seconds from the recording's first message (optional: the
    whole recording); ``reason`` required, since it is what the reports show."""
    folder = str(Path(where).parent)
    out = []
    for pattern, entries in _table(table["suppressions"], "suppressions", where).items():
        at = f"{where}: suppressions.{pattern!r}"
        try:
            glob_regex(pattern.removeprefix("!"))
        except (ValueError, re.error) as exc:
            raise ConfigError(f"{at}: bad pattern: {exc}") from None
        if isinstance(entries, dict):
            entries = [entries]
        if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
            raise ConfigError(f"{at} must be a list of tables, e.g. {_SUPPRESSION_EXAMPLE}")
        for entry in entries:
            unknown = sorted(set(entry) - _SUPPRESSION_KEYS)
            if unknown:
                raise ConfigError(
                    f"{at}: unknown key {unknown[0]}{did_you_mean(unknown[0], _SUPPRESSION_KEYS)}"
                    f"; known: code, from, to, reason"
                )
            if "code" not in entry:
                raise ConfigError(f"{at}: each suppression names its code: {_SUPPRESSION_EXAMPLE}")
            reason = entry.get("reason")
            if not isinstance(reason, str) or not reason.strip():
                raise ConfigError(
                    f"{at}: each suppression gives its reason (the reports show it): "
                    f"{_SUPPRESSION_EXAMPLE}"
                )
            window = [_seconds(entry.get(k), f"{at}: {k}") for k in ("from", "to")]
            if window[0] is not None and window[1] is not None and window[0] > window[1]:
                raise ConfigError(f"{at}: from ({window[0]}) is after to ({window[1]})")
            codes = _codes(
                [entry["code"]] if isinstance(entry["code"], str) else entry["code"], "code", at
            )
            out.append(
                ConfigSuppression(
                    pattern, folder, frozenset(codes), reason.strip(), where, window[0], window[1]
                )
            )
    return out


def _seconds(value: Any, where: str) -> float | None:
    if value is None:
        return None
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
        raise ConfigError(f"{where} must be a number of seconds")
    return float(value)


def _file_ignores(table: Mapping[str, Any], where: str) -> list[FileIgnore]:
    """``per-file-ignores = { "GLOB" = ["CODE", ...] }``, patterns relative to the file's
    folder."""
    folder = str(Path(where).parent) if where != "command line" else os.getcwd()
    out = []
    for pattern, codes in _table(table["per-file-ignores"], "per-file-ignores", where).items():
        try:
            glob_regex(pattern.removeprefix("!"))
        except (ValueError, re.error) as exc:
            raise ConfigError(
                f"{where}: per-file-ignores: bad pattern {pattern!r}: {exc}"
            ) from None
        chosen = _codes(codes, f"per-file-ignores.{pattern!r}", where)
        out.append(FileIgnore(pattern, folder, frozenset(chosen)))
    return out


def load_settings(
    start: Path | None = None,
    overrides: Mapping[str, Any] | None = None,
    *,
    per_recording: bool = False,
    config: Path | None = None,
) -> Settings:
    """Settings from the nearest config file, then ``overrides`` (the command line) on top.

    ``per_recording`` (command-line runs): ``Settings.for_recording`` then looks for each
    recording's own nearest configuration, as ruff does for each source file. ``config``
    (``--config FILE``, as ruff's): that file for every recording, none searched for."""
    clean = {k: v for k, v in (overrides or {}).items() if v is not None}
    if config is not None:
        if not config.is_file():
            raise ConfigError(f"--config {config}: no such file")
        if config.name == "pyproject.toml" and "fuzzoff" not in _load_toml(config).get("tool", {}):
            raise ConfigError(f"--config {config}: no [tool.fuzzoff] table in it")
        return _settings_from(config.resolve(), clean)
    settings = _settings_from(find_config((start or Path.cwd()).resolve()), clean)
    if per_recording:
        settings = replace(settings, discovery=Discovery(tuple(sorted(clean.items()))))
    return settings


def _settings_from(config: Path | None, overrides: Mapping[str, Any]) -> Settings:
    settings = Settings()
    if config is not None:
        settings = settings_from_table(read_config_table(config), str(config), settings)
        settings = replace(settings, config_file=str(config))
    if overrides:
        if "select" in overrides:
            # as in ruff: --select names the rules outright, the file's ignore included
            settings = replace(settings, ignore=frozenset())
        settings = settings_from_table(overrides, "command line", settings)
    return settings


def _nearest_settings(run: Settings, discovery: Discovery, recording: Path) -> Settings:
    """The settings of the nearest configuration above ``recording``; the run's own when there
    is none, or when it is the run's. ``fail-on`` stays the run's: a run has one exit status."""
    folder = os.path.abspath(recording)
    if not os.path.isdir(folder):
        folder = os.path.dirname(folder)
    found = discovery.cache.get(folder)
    if found is None:
        config = find_config(Path(folder))
        if config is None or str(config) == run.config_file:
            found = run
        else:
            found = discovery.cache.get(str(config))
            if found is None:
                found = _settings_from(config, dict(discovery.overrides))
                found = replace(
                    found,
                    fail_on=run.fail_on,
                    exit_zero=run.exit_zero,
                    notes=_fail_on_note(found, run),
                )
                discovery.cache[str(config)] = found
        discovery.cache[folder] = found
    return found


def _fail_on_note(nested: Settings, run: Settings) -> tuple[str, ...]:
    table = read_config_table(Path(nested.config_file or ""))
    if "fail-on" not in table or nested.fail_on is run.fail_on:
        return nested.notes
    where = run.config_file or "the default"
    return (
        *nested.notes,
        f"{nested.config_file}: fail-on is not used: one run has one exit status, set by "
        f"--fail-on or the configuration of the folder fuzzoff runs in ({where}: "
        f"{run.fail_on.label})",
    )
