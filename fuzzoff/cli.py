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


def build_parser() -> argparse.ArgumentParser:
    from fuzzoff import commands

    parser = _Parser(
        prog="fuzzoff",
        description="Lint and fuzz PX4 offboard setpoint streams.",
    )
    parser.add_argument("--version", action="version", version=f"fuzzoff {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for info in sorted(pkgutil.iter_modules(commands.__path__), key=lambda m: m.name):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"fuzzoff.commands.{info.name}")
        module.add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    try:
        parser = build_parser()
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
