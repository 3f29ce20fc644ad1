"""What ``fuzzoff lint`` does once the recordings are linted, wherever they were (this
process, worker processes, a Dask cluster): the suppressions and the baseline (docs/reports.md,
"Adopting fuzzoff on a fleet"), each report asked for, one stderr line per damaged part of a
recording; and ``--show-settings``."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from fuzzoff.commands._common import _output_file, render_rich, write_output
from fuzzoff.config import ConfigError, Settings
from fuzzoff.findings import Report
from fuzzoff.report import renderer
from fuzzoff.report.sanitize import printable


def add_adoption_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--baseline",
        metavar="FILE",
        help="report as suppressed the findings this baseline holds (see --write-baseline)",
    )
    parser.add_argument(
        "--write-baseline",
        metavar="FILE",
        help="write every finding of this lint to FILE, for --baseline; exits 0 on findings",
    )
    parser.add_argument(
        "--show-settings",
        metavar="PATH",
        help="print the settings and profile one recording is judged with, then stop",
    )


def check_baseline(args: argparse.Namespace) -> frozenset[tuple[str, str]] | None:
    """The ``--baseline`` read before any work: a file that is no baseline is a usage error
    now, not after an hour of linting."""
    from fuzzoff.suppress import read_baseline

    return None if args.baseline is None else read_baseline(Path(args.baseline))


def settle(
    args: argparse.Namespace,
    report: Report,
    settings: Settings,
    settings_for: Callable[[str], Settings],
    baseline: frozenset[tuple[str, str]] | None,
) -> Settings:
    """The configuration's suppressions, then ``--write-baseline`` (the findings left), then
    ``--baseline``: the report as the reports show it. Returns the run's settings, which
    ``--write-baseline`` makes exit 0 on findings (the point is to record them)."""
    from fuzzoff.suppress import apply_baseline, apply_config, write_baseline

    apply_config(report, settings_for)
    if args.write_baseline is not None:
        count = write_baseline(report, Path(args.write_baseline))
        print(
            f"fuzzoff: {count} finding(s) of {len(report.files)} recording(s) written to "
            f"{args.write_baseline}",
            file=sys.stderr,
        )
        settings = replace(settings, exit_zero=True)
    if baseline is not None:
        apply_baseline(report, baseline, Path(args.baseline))
    return settings


def write_report(
    args: argparse.Namespace, report: Report, settings: Settings, fmt: str, output: str | None
) -> None:
    """One report in ``fmt`` to ``output`` (None: standard output)."""
    if fmt == "terminal":
        _terminal(args, report, settings, output)
    else:
        write_output(renderer(fmt)(report, settings), output)


def _terminal(
    args: argparse.Namespace, report: Report, settings: Settings, output: str | None
) -> None:
    from fuzzoff.report.plain import plain_report, plain_width

    width = plain_width(to_file=_output_file(output) is not None)
    if width is not None:  # not a terminal: the same text without rich (issue 31)
        text = plain_report(
            report,
            settings.fail_on,
            width,
            quiet=args.quiet,
            statistics=args.statistics,
            verbose=args.verbose,
            exit_zero=settings.exit_zero,
        )
        if text is not None:
            write_output(text, output)
            return
    from rich.console import Console

    from fuzzoff.report.terminal import print_report

    def draw(console: Console) -> None:
        print_report(
            console,
            report,
            settings.fail_on,
            quiet=args.quiet,
            statistics=args.statistics,
            verbose=args.verbose,
            exit_zero=settings.exit_zero,
        )

    render_rich(draw, output)


def print_problems(report: Report, settings: Settings) -> None:
    """A line on stderr for each part of a recording not read (and read around, unless OFB004
    is silenced: nothing was lost)."""
    malformed = settings.enabled("OFB004")
    for f in report.files:
        for line in [*f.problems, *(f.malformed if malformed else [])]:
            print(f"fuzzoff: {printable(line)}", file=sys.stderr)


def show_settings(path: str, settings: Settings) -> int:
    """``--show-settings PATH``: what one recording is judged with, as ruff's: the
    configuration found for it, the command line on top, and the profile its lint takes."""
    from fuzzoff.catalog import load_catalog
    from fuzzoff.engine import lint_file
    from fuzzoff.formats import recordings_in

    found = recordings_in([path]) if Path(path).exists() else []
    if len(found) != 1:
        what = "no recording" if not found else f"{len(found)} recordings"
        raise ConfigError(f"--show-settings {path}: {what} there; name one recording")
    recording = str(found[0])
    resolved = settings.resolved_for(recording)
    profile = lint_file(recording, resolved).profile
    source = {"recording": "detected", "user": "set by the user", "default": "assumed"}
    release = f", release {profile.px4_release}" if profile.px4_release else ""
    catalog = load_catalog()
    enabled = [code for code in catalog if resolved.enabled(code)]
    fail_on = resolved.fail_on.label + (" (never fails: --exit-zero)" if settings.exit_zero else "")
    rows = [
        ("recording", recording),
        ("configuration", resolved.config_file or "none found (defaults)"),
        ("px4", f"{profile.px4} ({source[profile.px4_source]}{release})"),
        ("vehicle", f"{profile.vehicle} ({source[profile.vehicle_source]})"),
        ("rules", f"{len(enabled)} of {len(catalog)} enabled"),
        ("ignored", ", ".join(sorted(set(catalog) - set(enabled))) or "none"),
        ("fail-on", fail_on),
        ("severity", ", ".join(f"{c}={v.label}" for c, v in sorted(resolved.severity.items()))),
        (
            "options",
            ", ".join(
                f"{code}.{name}={value}"
                for code, values in sorted(resolved.options.items())
                for name, value in sorted(values.items())
            ),
        ),
        (
            "params",
            ", ".join(
                f"{name}={value:g} ({resolved.param_origin(name)})"
                for name, value in sorted(resolved.params.items())
            ),
        ),
    ]
    for entry in resolved.suppressions:
        window = (
            "whole recording"
            if entry.from_s is None and entry.to_s is None
            else f"{entry.from_s if entry.from_s is not None else 0:g}-"
            f"{entry.to_s if entry.to_s is not None else 'end'} s"
        )
        rows.append(("suppression", f"{','.join(sorted(entry.codes))} {window}: {entry.reason}"))
    lines = [f"{key:<14} {printable(value) if value else '-'}" for key, value in rows]
    write_output("\n".join(lines) + "\n", None)
    return 0
