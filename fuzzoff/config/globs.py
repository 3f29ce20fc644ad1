"""Globs for ``per-file-ignores``, as ruff reads them: which recordings an entry matches.

One idea of the configuration kept apart from the others (``config.py``: the settings, their
validation and where they are found): a pattern and the folder it is relative to in, a match
out.
"""

from __future__ import annotations

import functools
import os
import re
from pathlib import Path

from fuzzoff.lean_dataclass import dataclass


@dataclass(frozen=True, slots=True)
class FileIgnore:
    """One ``per-file-ignores`` entry: codes turned off in the recordings its glob matches.

    As in ruff, a pattern without a slash matches a recording's name in any folder; one with a
    slash matches its path relative to the configuration's folder (``*`` stays within a
    folder, ``**`` spans folders); a leading ``!`` turns off the codes everywhere the rest of
    the pattern does not match."""

    pattern: str
    folder: str
    codes: frozenset[str]

    def matches(self, recording: str | Path) -> bool:
        negated = self.pattern.startswith("!")
        pattern = self.pattern[1:] if negated else self.pattern
        path = Path(os.path.abspath(recording))
        if "/" not in pattern:
            hit = glob_regex(pattern).fullmatch(path.name) is not None
        else:
            try:
                relative = path.relative_to(os.path.abspath(self.folder)).as_posix()
            except ValueError:
                relative = path.as_posix()
            target = path.as_posix() if pattern.startswith("/") else relative
            hit = glob_regex(pattern.removeprefix("./")).fullmatch(target) is not None
        return hit != negated


@functools.lru_cache(maxsize=256)
def glob_regex(pattern: str) -> re.Pattern[str]:
    """A glob as a regular expression: ``*``/``?`` within one path part, ``**`` across parts,
    ``[...]`` classes (``[!...]`` negated) and ``{a,b}`` alternatives."""
    out: list[str] = []
    i, depth = 0, 0
    while i < len(pattern):
        c = pattern[i]
        if pattern.startswith("**/", i):
            out.append("(?:.*/)?")
            i += 3
            continue
        if pattern.startswith("**", i):
            out.append(".*")
            i += 2
            continue
        if c == "*":
            out.append("[^/]*")
        elif c == "?":
            out.append("[^/]")
        elif c == "[" and "]" in pattern[i + 2 :]:
            end = pattern.index("]", i + 2)
            body = pattern[i + 1 : end]
            if body.startswith("!"):
                body = "^" + body[1:]
            out.append("[" + body.replace("\\", "\\\\") + "]")
            i = end
        elif c == "{":
            out.append("(?:")
            depth += 1
        elif c == "}" and depth:
            out.append(")")
            depth -= 1
        elif c == "," and depth:
            out.append("|")
        else:
            out.append(re.escape(c))
        i += 1
    if depth:
        raise ValueError(f"unclosed {{ in {pattern!r}")
    return re.compile("".join(out))
