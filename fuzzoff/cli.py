"""The ``fuzzoff`` command: a thin layer over the Python API.

Each subcommand lives in ``fuzzoff/commands/<name>.py`` with ``add_parser(subparsers)`` and
``run(args) -> int``; this module finds them, parses, and turns usage errors into exit status 2.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from collections.abc import Sequence

from fuzzoff import __version__
from fuzzoff.config import ConfigError


class UsageError(Exception):
    """A mistake on the command line: one line on stderr, exit status 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        raise UsageError(f"{self.prog}: {message}")


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The parser; with ``only``, just that subcommand's module is imported (``fuzz`` pulls in
    Hypothesis, which a ``lint`` run need not pay for at start-up)."""
    from fuzzoff import commands

    parser = _Parser(
        prog="fuzzoff",
        description="Lint and fuzz PX4 offboard setpoint streams.",
    )
    parser.add_argument("--version", action="version", version=f"fuzzoff {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    names = [m.name for m in pkgutil.iter_modules(commands.__path__) if not m.name.startswith("_")]
    if only in names:
        names = [only]
    for name in sorted(names):
        module = importlib.import_module(f"fuzzoff.commands.{name}")
        module.add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        parser = build_parser(only=argv[0] if argv else None)
        args = parser.parse_args(argv)
        status: int = args.run(args)
        return status
    except (UsageError, ConfigError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
