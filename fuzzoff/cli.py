"""The ``fuzzoff`` command: a thin layer over the Python API.

Each subcommand lives in ``fuzzoff/commands/<name>.py`` with ``add_parser(subparsers)`` and
``run(args) -> int``, and a one-line summary in ``fuzzoff.commands.SUMMARIES``; this module
imports the one named on the command line, parses, and turns usage errors into exit status 2.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
from collections.abc import Sequence
from typing import Any

from fuzzoff._version import __version__
from fuzzoff.commands import SUMMARIES, add_command
from fuzzoff.usage import ConfigError, did_you_mean


class UsageError(Exception):
    """A mistake on the command line: one line on stderr, exit status 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        raise UsageError(f"{self.prog}: {message}{self._suggestion(message)}")

    def _suggestion(self, message: str) -> str:
        """A did-you-mean for a mistyped option, command or choice, as ruff gives."""
        unknown = re.match(r"unrecognized arguments: (\S+)", message)
        if unknown and unknown.group(1).startswith("-"):
            word = unknown.group(1).split("=", 1)[0]
            return did_you_mean(word, self._option_strings())
        choice = re.search(r"invalid choice: '?([^' ]*)'? \(choose from (.*)\)", message)
        if choice:
            choices = re.findall(r"[\w-]+", choice.group(2))
            return did_you_mean(choice.group(1), choices)
        return ""

    def _option_strings(self) -> list[str]:
        """This parser's options and those of the subcommand parsers it holds."""
        found = list(self._option_string_actions)
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                for parser in action.choices.values():
                    found.extend(parser._option_string_actions)
        return found


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The parser. With ``only`` naming a subcommand, just that command's module is imported
    and its full parser built (the command line always names the command first). Otherwise
    (``fuzzoff --help``, a mistyped command) the subcommands are listed from their summaries,
    none imported: ``fuzz`` pulls in Hypothesis, which neither need pay for."""
    parser = _Parser(
        prog="fuzzoff",
        description="Lint and fuzz PX4 offboard setpoint streams.",
    )
    parser.add_argument("--version", action="version", version=f"fuzzoff {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in sorted(SUMMARIES):
        if only is None or only == name:
            _import_command(name).add_parser(sub)
        elif only not in SUMMARIES:
            add_command(sub, name)
    return parser


EXTRAS = {"hypothesis": "fuzz"}
"""A dependency left out of the plain install -> the extra that brings it."""


def _import_command(name: str) -> Any:
    """The subcommand's module; one that needs an extra the install left out is a usage error
    saying how to add it (``fuzz`` needs Hypothesis: a plain ``pip install fuzzoff`` stays
    lean for ``lint``)."""
    try:
        return importlib.import_module(f"fuzzoff.commands.{name}")
    except ModuleNotFoundError as exc:
        missing = (exc.name or "").partition(".")[0]
        if missing not in EXTRAS:
            raise
        raise UsageError(
            f"fuzzoff {name} needs {missing}, which a plain install leaves out: "
            f"pip install 'fuzzoff[{EXTRAS[missing]}]'"
        ) from None


def main(argv: Sequence[str] | None = None) -> int:
    # fuzzoff multiplies no large matrices: numpy's OpenBLAS would start a thread per core when
    # pyulog imports numpy, half of that import's CPU (0.07 s of a 0.3 s ULog lint, issue 31).
    # Set for this process and its workers, unless the user chose a number.
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        parser = build_parser(only=argv[0] if argv else "")
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
