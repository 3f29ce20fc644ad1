"""A configuration table (``[tool.fuzzoff]``, a ``fuzzoff.toml``, the command line's values)
read and checked into ``Settings``: an unknown key, code or option is a usage error, never
ignored; ``--px4`` and ``--vehicle`` become a release record's name and a vehicle type."""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

from fuzzoff import releases
from fuzzoff.catalog import expand_selectors, get_rule, load_catalog
from fuzzoff.config.errors import ConfigError, did_you_mean
from fuzzoff.config.globs import FileIgnore, glob_regex
from fuzzoff.config.settings import ConfigSuppression, Settings
from fuzzoff.findings import Severity
from fuzzoff.gate.params import GATE_PARAMS
from fuzzoff.profiles import (
    VEHICLE_TYPES,
    ProfileError,
    px4_profile_for,
    vehicle_type_for,
)
from fuzzoff.releases import PX4Profile

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
    release = releases.version_of(name)
    if release is None:
        raise ProfileError(
            f"unknown PX4 version {text!r}{did_you_mean(name, known)}: give a release "
            f"such as 1.15.4, or one of {', '.join(known)}"
        )
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
    setpoints differently (gate spec 10), and a guess would judge the wrong one."""
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


def load_toml(path: Path) -> dict[str, Any]:
    return parse_toml(toml_text(path), path)


def toml_text(path: Path) -> str:
    """A TOML file's text: one that cannot be read or is not UTF-8 is a ``ConfigError``."""
    try:
        return path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{path}: not UTF-8 text (byte {exc.start}), as TOML must be") from None
    except OSError as exc:
        raise ConfigError(f"{path}: cannot be read: {exc.strerror or exc}") from None


def parse_toml(text: str, path: Path) -> dict[str, Any]:
    """``text`` (read from ``path``) as TOML; not valid TOML is a ``ConfigError``."""
    import tomllib  # only where a configuration file is found

    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None


def read_config_table(path: Path) -> dict[str, Any]:
    data = load_toml(path)
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
        from difflib import get_close_matches  # only for a typo: not loaded by every lint

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
