"""A fleet's recordings: lint on a Dask cluster, from fsspec URLs, into a Parquet dataset.

Needs the ``fleet`` extra (``pip install 'fuzzoff[fleet]'``: dask, distributed, fsspec, aiohttp,
pyarrow); the lint core never imports this package's dependencies. ``require`` turns a missing
one into one usage line. See docs/fleet.md.
"""

from __future__ import annotations

import importlib.util
import re

from fuzzoff.config import ConfigError

EXTRA = "pip install 'fuzzoff[fleet]'"

_NEEDS = {
    "scheduler": ("dask", "distributed"),
    "urls": ("fsspec",),
    "parquet": ("pyarrow",),
}


def require(what: str, option: str) -> None:
    """Raise one usage line when ``option`` needs a module of the fleet extra that is missing."""
    missing = [m for m in _NEEDS[what] if importlib.util.find_spec(m) is None]
    if missing:
        raise ConfigError(f"{option} needs {', '.join(missing)}: {EXTRA}")


_URL = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*://")


def is_url(text: str) -> bool:
    """``s3://bucket/key``, ``https://...``, ``file:///...``: a recording fsspec fetches."""
    return bool(_URL.match(text))
