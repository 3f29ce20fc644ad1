"""Where the settings come from: the nearest ``fuzzoff.toml``, or ``pyproject.toml`` with a
``[tool.fuzzoff]`` table, then the command line; and, as in ruff, each recording's own nearest
configuration (``NearestConfig``)."""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import field, replace
from pathlib import Path
from typing import Any

from fuzzoff.config.errors import ConfigError
from fuzzoff.config.settings import Settings
from fuzzoff.config.table import (
    load_toml,
    parse_toml,
    read_config_table,
    settings_from_table,
    toml_text,
)
from fuzzoff.lean_dataclass import dataclass


def find_config(start: Path) -> Path | None:
    """The nearest fuzzoff.toml, or pyproject.toml with a ``[tool.fuzzoff]`` table.

    A pyproject.toml that cannot be read is an error, not skipped: it may hold the table, and
    a parent folder's settings would silently take its place. One whose text cannot name the
    table (``_may_name_fuzzoff``) is passed by unparsed, as if it had no table."""
    for folder in [start, *start.parents]:
        candidate = folder / "fuzzoff.toml"
        if candidate.is_file():
            return candidate
        candidate = folder / "pyproject.toml"
        if not candidate.is_file():
            continue
        text = toml_text(candidate)
        if _may_name_fuzzoff(text):
            tool = parse_toml(text, candidate).get("tool", {})
            if isinstance(tool, dict) and "fuzzoff" in tool:
                return candidate
    return None


def _may_name_fuzzoff(text: str) -> bool:
    """Whether a pyproject.toml's text could hold a ``[tool.fuzzoff]`` table: the key written
    out, or a quoted key spelled with escapes (``"fuzz\\u006Fff"``). Most projects' files do
    neither and are not parsed: tomllib's import and parse were some 25 M instructions of every
    lint run in such a project (issue 31)."""
    return "fuzzoff" in text or "\\u" in text or "\\U" in text


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
        if config.name == "pyproject.toml" and "fuzzoff" not in load_toml(config).get("tool", {}):
            raise ConfigError(f"--config {config}: no [tool.fuzzoff] table in it")
        return _settings_from(config.resolve(), clean)
    settings = _settings_from(find_config((start or Path.cwd()).resolve()), clean)
    if per_recording:
        settings = replace(settings, discovery=NearestConfig(tuple(sorted(clean.items()))))
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


@dataclass(frozen=True, slots=True)
class NearestConfig:
    """What a run needs to find each recording's settings: the command line's values, laid over
    the nearest configuration above the recording (``Settings.for_recording``)."""

    overrides: tuple[tuple[str, Any], ...]
    cache: dict[str, Settings] = field(default_factory=dict, compare=False, hash=False)

    def settings_for(self, run: Settings, recording: Path) -> Settings:
        """The settings of the nearest configuration above ``recording``; the run's own when
        there is none, or when it is the run's. ``fail-on`` stays the run's: a run has one
        exit status."""
        folder = os.path.abspath(recording)
        if not os.path.isdir(folder):
            folder = os.path.dirname(folder)
        found = self.cache.get(folder)
        if found is None:
            config = find_config(Path(folder))
            if config is None or str(config) == run.config_file:
                found = run
            else:
                found = self.cache.get(str(config))
                if found is None:
                    found = _settings_from(config, dict(self.overrides))
                    found = replace(
                        found,
                        fail_on=run.fail_on,
                        exit_zero=run.exit_zero,
                        notes=_fail_on_note(found, run),
                    )
                    self.cache[str(config)] = found
            self.cache[folder] = found
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
