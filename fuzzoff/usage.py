"""The usage error every command reports as one line and exit status 2, and the did-you-mean
that goes with it. Kept apart from ``config`` so that ``fuzzoff --version`` and the command
line parser need not import the catalog, the profiles and the gate model to name them."""

from __future__ import annotations

from collections.abc import Iterable


class ConfigError(ValueError):
    """A usage error in the configuration or the command line (exit status 2)."""


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """`` (did you mean X?)`` for the closest choice, or nothing."""
    from difflib import get_close_matches  # only on a mistake: not paid by every start

    close = get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return f" (did you mean {close[0]}?)" if close else ""
