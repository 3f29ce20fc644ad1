"""Text from a recording is untrusted: make it safe for a terminal, a CI view or a JSON file."""

from __future__ import annotations

import re

_BIDI = "\u061c\u200e\u200f\u202a-\u202e\u2066-\u2069"
"""Characters that reorder the text around them (Trojan Source, CVE-2021-42574): the Arabic
letter mark, left-to-right and right-to-left marks, embeddings, overrides and isolates."""
_UNPRINTABLE = re.compile(f"[\\x00-\\x1f\\x7f-\\x9f\\u2028\\u2029{_BIDI}]")
_REORDERING = re.compile(f"[\\u2028\\u2029{_BIDI}]")
_BIDI_ONLY = re.compile(f"[{_BIDI}]")


CI_TEXT_LIMIT = 2000
"""Longest finding text in a CI view (JUnit, SARIF): a recording can make a message any length."""


def _written_out(match: re.Match[str]) -> str:
    code = ord(match.group())
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def printable(text: str, limit: int = 500) -> str:
    """Control characters (ANSI escapes, bidi overrides, line breaks and tabs too: each item
    printed stays on its line) shown as ``\\xNN`` or ``\\uNNNN``; long text cut."""
    safe = _UNPRINTABLE.sub(_written_out, text)
    return safe if len(safe) <= limit else safe[: limit - 1] + "…"


def escape_bidi(text: str) -> str:
    """Every bidi control and line separator in ``text`` as a ``\\uNNNN`` escape, so nothing
    reorders the text where a person reads it (an editor, a code review, a CI view). In JSON
    from ``json.dumps(..., ensure_ascii=False)`` such characters only occur inside strings,
    where the escape means the character itself: parsers get the same strings back. In XML
    (JUnit) the escape is shown as written, as on the terminal."""
    return _REORDERING.sub(lambda m: f"\\u{ord(m.group()):04x}", text)


def show_bidi(text: str) -> str:
    """Bidi controls in ``text`` written out as ``\\uNNNN`` (the rest as it is): for strings a
    script draws as labels, where a control would reorder what is shown."""
    return _BIDI_ONLY.sub(lambda m: f"\\u{ord(m.group()):04x}", text)
