"""``fuzzoff lint`` for a fleet: ``--scheduler``, URLs, ``--format parquet`` (docs/fleet.md).

The same reports, stderr lines and exit status as a plain lint: every recording is linted by
``lint_file`` and the file reports go to the same renderers. What differs is where the lint
runs (Dask tasks, or this machine's processes), where recordings come from (fsspec URLs) and
one more output, the Parquet dataset.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Collection, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from functools import partial
from pathlib import Path

from fuzzoff.commands._common import (
    check_output,
    existing_paths,
    report_targets,
    settings_per_recording,
    write_output,
    write_stdout,
)
from fuzzoff.config import ConfigError, Settings
from fuzzoff.engine import lint_file
from fuzzoff.findings import Report
from fuzzoff.fleet import is_url, require
from fuzzoff.fleet.inputs import expand
from fuzzoff.fleet.task import LINTED, SKIPPED, Lint, Outcome, lint_target
from fuzzoff.formats import RECORDING_SUFFIXES, find_recordings
from fuzzoff.report import renderer
from fuzzoff.report.sanitize import printable

PARQUET = "parquet"


def targets_of(paths: Sequence[str]) -> list[str]:
    """The recordings named on the command line, as a plain lint finds them (local paths),
    URLs expanded on this machine (the workers fetch them)."""
    found: list[str] = []
    for p in paths:
        if is_url(p):
            require("urls", "a URL")
            found.extend(expand(p))
            continue
        existing_paths([p])
        recordings = find_recordings(Path(p))
        if Path(p).is_dir() and not recordings:
            suffixes = ", ".join(RECORDING_SUFFIXES)
            raise ConfigError(f"no recordings in {p} (searched for {suffixes} and bag folders)")
        found.extend(str(f) for f in recordings)
    return list(dict.fromkeys(found))


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


def run_fleet(
    args: argparse.Namespace,
    settings: Settings,
    terminal: Callable[[argparse.Namespace, Report, Settings, str | None], None],
) -> int:
    """The lint command when it runs on a cluster, reads URLs or writes the dataset;
    ``terminal`` draws the terminal report as the plain lint does."""
    reports = report_targets(args.format, args.output)
    check_fleet_args(args, reports)
    targets = targets_of(args.paths)
    local = [t for t in targets if not is_url(t)]
    for fmt, output in reports:
        if fmt != PARQUET:
            check_output(output, local)
    settings_per_recording(settings, local)
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
            targets,
            settings,
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
        elif fmt == "terminal":
            terminal(args, report, settings, output)
        else:
            write_output(renderer(fmt)(report, settings), output)
    malformed = settings.enabled("OFB004")  # as a plain lint: read around, may be silenced
    for f in report.files:
        for line in [*f.problems, *(f.malformed if malformed else [])]:
            print(f"fuzzoff: {printable(line)}", file=sys.stderr)
    return report.exit_status(settings.fail_on)


def lint_all(
    targets: Sequence[str],
    settings: Settings,
    *,
    scheduler: str | None,
    jobs: int = 1,
    timeout_s: float | None = None,
    lint: Lint = lint_file,
    known: Collection[str] = (),
    record: bool = False,
    on_outcome: Callable[[Outcome], None] | None = None,
) -> list[Outcome]:
    """Every target's outcome, in the order given: on the Dask cluster at ``scheduler``
    (``local`` starts one with ``jobs`` worker processes, as many as ``--jobs`` would use),
    else in ``jobs`` processes here."""
    if scheduler is not None:
        from fuzzoff.fleet.cluster import DEFAULT_TIMEOUT_S, connect, run_on_cluster

        with connect(scheduler, jobs) as client:
            return run_on_cluster(
                client,
                targets,
                settings,
                timeout_s=timeout_s or DEFAULT_TIMEOUT_S,
                lint=lint,
                known=known,
                record=record,
                on_outcome=on_outcome,
            )
    work = partial(_lint_here, settings=settings, lint=lint, record=record)
    outcomes: list[Outcome] = []
    if jobs > 1 and len(targets) > 1:
        with ProcessPoolExecutor(jobs, initializer=_know, initargs=(frozenset(known),)) as pool:
            for outcome in pool.map(work, targets):
                outcomes.append(outcome)
                if on_outcome is not None:
                    on_outcome(outcome)
        return outcomes
    _know(frozenset(known))
    for target in targets:
        outcome = work(target)
        outcomes.append(outcome)
        if on_outcome is not None:
            on_outcome(outcome)
    return outcomes


_KNOWN: frozenset[str] = frozenset()
"""The dataset's hashes in a local worker process (set once by the pool's initializer, not
sent with every recording)."""


def _know(known: frozenset[str]) -> None:
    global _KNOWN
    _KNOWN = known


def _lint_here(target: str, *, settings: Settings, lint: Lint, record: bool) -> Outcome:
    return lint_target(target, settings, lint=lint, known=_KNOWN, record=record)


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
