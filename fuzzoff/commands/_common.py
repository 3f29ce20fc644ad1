"""Options shared by the commands that judge recordings, and how they become ``Settings``."""

from __future__ import annotations

import argparse
import io
import math
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fuzzoff.config import ConfigError, Settings, load_settings
from fuzzoff.report import FORMATS

if TYPE_CHECKING:
    from rich.console import Console


def add_profile_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--px4", metavar="VERSION", help="PX4 release (1.15.4) or profile (legacy, main)"
    )
    parser.add_argument("--vehicle", metavar="TYPE", help="mc, fw, vtol, rover-ackermann, ...")
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="override a PX4 parameter for the gate model (repeatable), e.g. COM_OF_LOSS_T=0.5",
    )


def add_rule_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--select", metavar="CODES", help="comma-separated codes or prefixes (OFB1)"
    )
    parser.add_argument("--extend-select", metavar="CODES", help="add to the selected rules")
    parser.add_argument("--ignore", metavar="CODES", help="comma-separated codes or prefixes")
    parser.add_argument(
        "--fail-on",
        choices=("error", "warning", "info"),
        help="lowest severity that makes the exit status 1 (default warning)",
    )


def add_output_options(parser: argparse.ArgumentParser, formats: tuple[str, ...] = FORMATS) -> None:
    parser.add_argument("--format", choices=formats, default="terminal")
    parser.add_argument("--output", "-o", metavar="FILE", help="write the report here")


def add_report_options(parser: argparse.ArgumentParser, formats: tuple[str, ...] = FORMATS) -> None:
    """``--format`` and ``--output`` that may repeat, in pairs: one lint, several reports. An
    ``--output`` belongs to the ``--format`` just before it, as the line reads (``--format
    terminal --format html -o r.html`` writes the HTML to r.html, the text to the screen)."""
    parser.add_argument(
        "--format",
        action=_FormatAction,
        choices=formats,
        help="report format (default terminal); repeat it, each with its --output, for several",
    )
    parser.add_argument(
        "--output",
        "-o",
        action=_OutputAction,
        metavar="FILE",
        help="where the --format just before it goes (default and '-': standard output)",
    )


class _FormatAction(argparse.Action):
    """``--format``: one more report, to standard output until an ``--output`` follows it.
    ``args.format`` and ``args.output`` stay the same length, an output None until given."""

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        namespace.format = [*(namespace.format or []), values]
        namespace.output = [*(namespace.output or []), None]


class _OutputAction(argparse.Action):
    """``--output``: the file of the ``--format`` just before it, which must have none yet."""

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        outputs = list(namespace.output or [])
        if not outputs or outputs[-1] is not None:
            parser.error(
                f"{option_string} {values} has no --format before it: give each --output "
                "after its own --format (--format html --output report.html)"
            )
        outputs[-1] = values
        namespace.output = outputs


def report_targets(
    formats: list[str] | None, outputs: list[str | None] | None
) -> list[tuple[str, str | None]]:
    """``--format``/``--output`` pairs in the order given: ``[("sarif", "a.sarif"), ("html",
    "r.html"), ("terminal", None)]``. ``outputs`` holds each format's output, None for none
    (``add_report_options`` keeps the two lists in step). A format without an output of its
    own goes to standard output, which only one report can."""
    formats = formats or ["terminal"]
    outputs = outputs or []
    pairs = [(fmt, outputs[i] if i < len(outputs) else None) for i, fmt in enumerate(formats)]
    pairs = [(fmt, None if out == "-" else out) for fmt, out in pairs]
    to_stdout = [fmt for fmt, out in pairs if out is None]
    if len(to_stdout) > 1:
        raise ConfigError(
            f"only one report can go to standard output ({' and '.join(to_stdout)} would): "
            "give an --output for each --format but one"
        )
    files = [out for _, out in pairs if out is not None]
    twice = sorted({out for out in files if files.count(out) > 1})
    if twice:
        raise ConfigError(f"--output {twice[0]} is named twice: one report a file")
    return pairs


def add_scheduler_option(parser: argparse.ArgumentParser, what: str) -> None:
    parser.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help=f"run {what} as Dask tasks: a scheduler's address (tcp://host:8786), or 'local' "
        "for a cluster on this machine (needs: pip install 'fuzzoff[fleet]'; docs/fleet.md)",
    )


def add_fleet_options(parser: argparse.ArgumentParser) -> None:
    """``lint`` on a fleet (docs/fleet.md): Dask, and the Parquet dataset's incremental runs."""
    add_scheduler_option(parser, "one task per recording")
    parser.add_argument(
        "--timeout",
        type=float,
        metavar="SECONDS",
        help="with --scheduler: a recording still linting after this is stopped and reported "
        "as OFB001 (default 600)",
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="--format parquet: lint recordings the dataset holds already",
    )


def parse_params(values: list[str]) -> dict[str, float]:
    params: dict[str, float] = {}
    for item in values:
        name, sep, value = item.partition("=")
        try:
            number = float(value)
            if not sep or not math.isfinite(number):
                raise ValueError
            params[name.strip().upper()] = number
        except ValueError:
            raise ConfigError(f"--param {item!r}: expected NAME=NUMBER (a finite number)") from None
    return params


def settings_from_args(args: argparse.Namespace) -> Settings:
    overrides: dict[str, Any] = {
        "px4": getattr(args, "px4", None),
        "vehicle": getattr(args, "vehicle", None),
        "select": getattr(args, "select", None),
        "extend-select": getattr(args, "extend_select", None),
        "ignore": getattr(args, "ignore", None),
        "fail-on": getattr(args, "fail_on", None),
    }
    params = parse_params(getattr(args, "param", []) or [])
    if params:
        overrides["params"] = params
    settings = load_settings(Path.cwd(), overrides, per_recording=True)
    print_notes(settings)
    return settings


def print_notes(settings: Settings) -> None:
    """What the user should know about their settings, one line each on standard error."""
    for note in settings.notes:
        print(f"fuzzoff: {note}", file=sys.stderr)


def resolve_recordings(settings: Settings, recordings: list[str]) -> list[tuple[str, Settings]]:
    """Each recording with the settings it is judged with, resolved once, before any work
    (``Settings.resolved_for``): a mistake in a recording's nearest configuration is a
    usage error now, not a failure halfway through the run. Their notes are printed once."""
    seen = set(settings.notes)
    plan = []
    for recording in recordings:
        resolved = settings.resolved_for(recording)
        plan.append((recording, resolved))
        for note in resolved.notes:
            if note not in seen:
                seen.add(note)
                print(f"fuzzoff: {note}", file=sys.stderr)
    return plan


def recordings_named(paths: list[str]) -> list[str]:
    """The recordings the command line names, found once, in order: a file as given, a bag
    folder as one recording, other folders searched; each real file once however often it is
    named; a URL (a fleet lint) expanded on this machine, its workers fetch it. A path that
    does not exist, or a folder with nothing to lint, is a usage error before any work: passing
    it would turn a CI job green without looking at a single flight."""
    # here, not at the top: the commands that read no recording need not import the readers
    from fuzzoff.fleet import is_url, require  # the fleet's dependencies are imported on use
    from fuzzoff.formats import RECORDING_SUFFIXES, find_recordings, recordings_in

    existing_paths([p for p in paths if not is_url(p)])
    named: list[list[Path] | str] = []
    for p in paths:
        if is_url(p):
            require("urls", "a URL")
            named.append(p)
            continue
        found = find_recordings(Path(p))
        if Path(p).is_dir() and not found:
            suffixes = ", ".join(RECORDING_SUFFIXES)
            raise ConfigError(f"no recordings in {p} (searched for {suffixes} and bag folders)")
        named.append(found)
    # each real file once (a link, ``./a`` and ``a``), where it is first named
    first = recordings_in(f for item in named if not isinstance(item, str) for f in item)
    k = 0
    out: list[str] = []
    for item in named:
        if isinstance(item, str):
            from fuzzoff.fleet.inputs import expand

            out.extend(expand(item))
            continue
        for f in item:
            if k < len(first) and f == first[k]:
                out.append(str(f))
                k += 1
    return list(dict.fromkeys(out))


def existing_paths(paths: list[str]) -> None:
    """Check each path names something: an empty one (an unset shell variable) would otherwise
    mean the current folder."""
    for p in paths:
        if not p or not Path(p).exists():
            raise ConfigError(f"no such file or folder: {p or repr(p)}")


def _output_file(output: str | None) -> Path | None:
    """The file ``--output`` names; None for standard output (not given, or ``-``)."""
    return None if output is None or output == "-" else Path(output)


def check_output(output: str | None, inputs: list[str]) -> None:
    """Refuse, before any work, an ``--output`` that is a folder or one of the recordings read
    (the report would replace the flight log)."""
    path = _output_file(output)
    if path is None:
        return
    if path.is_dir():
        raise ConfigError(f"--output {output} is a folder: name a file")
    if path.exists() and any(path.samefile(p) for p in inputs if Path(p).exists()):
        raise ConfigError(f"--output {output} is a recording being read: name another file")


def write_output(text: str, output: str | None) -> None:
    """The report to ``output`` (parents created), or to standard output for None or ``-``."""
    path = _output_file(output)
    if path is None:
        write_stdout(text)
        return
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise ConfigError(f"cannot write {output}: {exc.strerror or exc}") from None


def write_stdout(text: str) -> None:
    """Standard output, where a reader that stopped early (``| head``) is not an error: the
    command still ends with its own status. A full disk or a closed stream is one line."""
    stream = sys.stdout
    if stream is None:
        raise ConfigError("standard output is closed: name a file with --output")
    try:
        stream.write(text)
        stream.flush()
    except BrokenPipeError:
        # Python would report the pipe again when it flushes at exit: point stdout elsewhere
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, stream.fileno())
    except OSError as exc:
        raise ConfigError(f"cannot write to standard output: {exc.strerror or exc}") from None


def render_rich(draw: Callable[[Console], None], output: str | None = None) -> None:
    """Draw with rich into text, then write it as ``write_output`` does. On standard output the
    text has the colours and width of the terminal, if it is one; in a file it is plain."""
    from rich.console import Console

    buffer = io.StringIO()
    if _output_file(output) is None:
        screen = Console(highlight=False)
        console = Console(
            file=buffer,
            highlight=False,
            force_terminal=screen.is_terminal,
            width=screen.width,
        )
    else:
        console = Console(file=buffer, highlight=False, no_color=True, width=160)
    draw(console)
    write_output(buffer.getvalue(), output)


def check_save_dir(directory: Path, label: str | None = None) -> None:
    """Refuse a ``--save-dir`` that cannot hold reproducers before the campaign runs, not after
    it. The folders it lacks are made and removed again, so that the system says what is wrong
    (a file on the way, a folder that cannot be written) and a campaign that finds nothing
    leaves nothing behind. ``label`` names the folder in the message."""
    label = label or f"--save-dir {directory}"
    made: list[Path] = []
    folder = directory
    while not folder.is_dir() and folder != folder.parent:
        if folder.exists() or folder.is_symlink():
            raise ConfigError(f"{label}: {folder} is not a folder")
        made.append(folder)
        folder = folder.parent
    try:
        for missing in reversed(made):
            missing.mkdir()
        if not os.access(directory, os.W_OK | os.X_OK):
            raise ConfigError(f"{label}: the folder cannot be written")
    except OSError as exc:
        raise ConfigError(f"{label}: cannot create {exc.filename}: {exc.strerror or exc}") from None
    finally:
        for missing in made:
            if missing.is_dir():
                missing.rmdir()
