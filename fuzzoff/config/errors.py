"""The configuration's usage error, and the did-you-mean its messages (and the CLI's) end with.

Both live in ``fuzzoff.usage`` (the CLI names them without importing the configuration);
they are the same objects here."""

from __future__ import annotations

from fuzzoff.usage import ConfigError, did_you_mean

__all__ = ["ConfigError", "did_you_mean"]
