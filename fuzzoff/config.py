"""Settings: ``[tool.fuzzoff]`` of the nearest pyproject.toml or a fuzzoff.toml, then the CLI.

Keys (ruff-like): ``px4``, ``vehicle``, ``select``, ``extend-select``, ``ignore``, ``fail-on``,
``severity`` (table code -> level), ``options`` (table code -> table of thresholds),
``params`` (PX4 parameter overrides for the gate model). An unknown key, code or option is a
usage error, never ignored.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from difflib import get_close_matches
from pathlib import Path
from typing import Any

from fuzzoff.catalog import expand_selectors, get_rule, load_catalog
from fuzzoff.findings import Severity
from fuzzoff.gate.params import GATE_PARAMS
from fuzzoff.profiles import ProfileError, px4_profile_for, vehicle_type_for


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
}


@dataclass(frozen=True, slots=True)
class Settings:
    """Everything that changes what a lint run reports."""

    px4: str | None = None
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
    """Apply a ``[tool.fuzzoff]``-shaped table (or CLI values in the same shape) to ``base``."""
    settings = base or Settings()
    unknown = set(table) - KNOWN_KEYS
    if unknown:
        known = ", ".join(sorted(KNOWN_KEYS))
        raise ConfigError(f"{where}: unknown key(s) {', '.join(sorted(unknown))}; known: {known}")
    try:
        if table.get("px4") is not None:
            px4 = _text(table["px4"], "px4", where, "1.15")
            settings = replace(settings, px4=px4_profile_for(px4))
        if table.get("vehicle") is not None:
            vehicle = _text(table["vehicle"], "vehicle", where, "mc")
            settings = replace(settings, vehicle=vehicle_type_for(vehicle))
    except ProfileError as exc:
        raise ConfigError(f"{where}: {exc}") from None
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
        try:
            settings = replace(settings, fail_on=Severity.parse(fail_on))
        except ValueError as exc:
            raise ConfigError(f"{where}: fail-on: {exc}") from None
    if table.get("severity") is not None:
        levels = dict(settings.severity)
        for selector, level in _table(table["severity"], "severity", where).items():
            try:
                sev = Severity.parse(str(level))
            except ValueError as exc:
                raise ConfigError(f"{where}: severity.{selector}: {exc}") from None
            for code in _codes([selector], "severity", where):
                levels[code] = sev
        settings = replace(settings, severity=levels)
    if table.get("options") is not None:
        options = {k: dict(v) for k, v in settings.options.items()}
        for code, values in _table(table["options"], "options", where).items():
            try:
                rule = get_rule(code)
            except KeyError:
                raise ConfigError(f"{where}: options: unknown rule {code!r}") from None
            for name, value in _table(values, f"options.{code}", where).items():
                try:
                    default = rule.option(name).default
                except KeyError:
                    known = ", ".join(o.name for o in rule.options) or "none"
                    raise ConfigError(
                        f"{where}: options.{code}: unknown option {name!r} (known: {known})"
                    ) from None
                options.setdefault(rule.code, {})[name] = _option_value(
                    value, default, f"{where}: options.{code}.{name}"
                )
        settings = replace(settings, options=options)
    if table.get("params") is not None:
        params = dict(settings.params)
        for name, value in _table(table["params"], "params", where).items():
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                raise ConfigError(f"{where}: params.{name} must be a number")
            if not math.isfinite(value):
                raise ConfigError(f"{where}: params.{name} must be a finite number")
            params[_param_name(str(name), where)] = float(value)
        settings = replace(settings, params=params)
    return settings


def load_settings(
    start: Path | None = None, overrides: Mapping[str, Any] | None = None
) -> Settings:
    """Settings from the nearest config file, then ``overrides`` (the command line) on top."""
    settings = Settings()
    config = find_config((start or Path.cwd()).resolve())
    if config is not None:
        settings = settings_from_table(read_config_table(config), str(config), settings)
        settings = replace(settings, config_file=str(config))
    if overrides:
        clean = {k: v for k, v in overrides.items() if v is not None}
        if "select" in clean:
            # as in ruff: --select names the rules outright, the file's ignore included
            settings = replace(settings, ignore=frozenset())
        settings = settings_from_table(clean, "command line", settings)
    return settings
