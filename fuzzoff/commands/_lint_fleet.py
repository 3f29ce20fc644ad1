"""``fuzzoff lint`` for a fleet: ``--scheduler``, URLs, ``--format parquet`` (docs/fleet.md).

The same reports, stderr lines and exit status as a plain lint: every recording is linted by
``lint_file`` and the file reports go to the same renderers (``_lint_output``). What differs is
where the lint runs (``fleet.lint_run``: Dask tasks, or this machine's processes), where
recordings come from (fsspec URLs) and one more output, the Parquet dataset.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from fuzzoff.commands._common import (
    check_output,
    recordings_named,
    report_targets,
    resolve_recordings,
    write_stdout,
)
from fuzzoff.commands._lint_output import print_problems, write_report
from fuzzoff.config import ConfigError, Settings
from fuzzoff.engine import lint_file
from fuzzoff.findings import Report
from fuzzoff.fleet import is_url, require
from fuzzoff.fleet.lint_run import lint_all
from fuzzoff.fleet.task import LINTED, SKIPPED, Lint, Outcome

PARQUET = "parquet"


def check_fleet_args(args: argparse.Namespace, reports: list[tuple[str, str | None]]) -> None:
    if args.timeout is not None and args.scheduler is None:
        raise ConfigError("--timeout needs --scheduler (local processes cannot stop one recording)")
    if args.timeout is not None and not args.timeout > 0:
        raise ConfigError(f"--timeout {args.timeout:g}: expected seconds above 0")
    dataset = dataset_dir(reports)
    if args.force and dataset is None:
        raise ConfigError("--force applies to --format parquet (it lints known recordings again)")
    if any(fmt == PARQUET for fmt, _ in reports):
        require("parquet", "--format parquet")
        if dataset is None:
            raise ConfigError("--format parquet needs --output DIR (the dataset's folder)")
        if Path(dataset).exists() and not Path(dataset).is_dir():
            raise ConfigError(f"--output {dataset} is a file: --format parquet writes a folder")


def dataset_dir(reports: list[tuple[str, str | None]]) -> str | None:
    """The ``--output`` of ``--format parquet`` (None: not asked, or no folder given)."""
    return next((out for fmt, out in reports if fmt == PARQUET), None)


def run_fleet(args: argparse.Namespace, settings: Settings) -> int:
    """The lint command when it runs on a cluster, reads URLs or writes the dataset: the same
    reports, stderr lines and exit status as a plain lint."""
    reports = report_targets(args.format, args.output)
    check_fleet_args(args, reports)
    targets = recordings_named(args.paths)
    local = [t for t in targets if not is_url(t)]
    for fmt, output in reports:
        if fmt != PARQUET:
            check_output(output, local)
    # each local recording's settings resolved once, its notes printed, before any work; a
    # URL's fetched copy is judged with the command's own (fleet.task)
    resolved = dict(resolve_recordings(settings, local))
    plan = [(t, resolved.get(t, settings)) for t in targets]
    lint: Lint = lint_file
    if any(fmt == "html" for fmt, _ in reports):
        from fuzzoff.engine import lint_file_with_timelines

        lint = lint_file_with_timelines
    dataset = dataset_dir(reports)
    known: frozenset[str] = frozenset()
    writer = None
    if dataset is not None:
        from fuzzoff.fleet.dataset import DatasetError, RunInfo, Writer, known_hashes

        try:
            known = frozenset() if args.force else known_hashes(Path(dataset))
        except DatasetError as exc:
            raise ConfigError(str(exc)) from None
        writer = Writer(Path(dataset), RunInfo.now())
    with _progress(len(targets), enabled=not args.no_progress) as advance:

        def on_outcome(outcome: Outcome) -> None:
            if writer is not None:
                writer.add(outcome)
            advance(outcome)

        outcomes = lint_all(
            plan,
            scheduler=args.scheduler,
            jobs=args.jobs,
            timeout_s=args.timeout,
            lint=lint,
            known=known,
            record=writer is not None,
            on_outcome=on_outcome,
        )
    report = Report([o.report for o in outcomes if o.report is not None])
    for fmt, output in reports:
        if fmt == PARQUET and writer is not None:
            writer.flush()
            summary = _dataset_summary(outcomes, writer.findings, str(output))
            if any(out is None for _, out in reports):  # another report has standard output
                print(summary, end="", file=sys.stderr)
            else:
                write_stdout(summary)
        else:
            write_report(args, report, settings, fmt, output)
    print_problems(report, settings)
    return report.exit_status(settings.fail_on)


@contextmanager
def _progress(total: int, *, enabled: bool) -> Iterator[Callable[[Outcome], None]]:
    """A rich progress bar on standard error, when it is a terminal: recordings done, skipped
    and not finished so far."""
    from rich.console import Console

    console = Console(stderr=True)
    if not enabled or not console.is_terminal or total < 2:
        yield lambda _: None
        return
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    columns = (
        TextColumn("lint"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[note]}"),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
    )
    counts = {"skipped": 0, "not finished": 0}
    with Progress(*columns, console=console, transient=True) as bar:
        task = bar.add_task("lint", total=total, note="")

        def advance(outcome: Outcome) -> None:
            if outcome.status == SKIPPED:
                counts["skipped"] += 1
            elif outcome.status != LINTED:
                counts["not finished"] += 1
            note = ", ".join(f"{n} {what}" for what, n in counts.items() if n)
            bar.update(task, advance=1, note=note)

        yield advance


def _dataset_summary(outcomes: Sequence[Outcome], findings: int, output: str) -> str:
    linted = sum(1 for o in outcomes if o.status == LINTED)
    skipped = sum(1 for o in outcomes if o.status == SKIPPED)
    unfinished = len(outcomes) - linted - skipped
    parts = [f"{linted} linted"]
    if skipped:
        parts.append(f"{skipped} skipped (already in {output}; --force lints them again)")
    if unfinished:
        parts.append(f"{unfinished} did not finish (OFB001; tried again next run)")
    return (
        f"fuzzoff: {len(outcomes)} recordings: {'; '.join(parts)}; "
        f"{findings} findings written to {output}\n"
    )
