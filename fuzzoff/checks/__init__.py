"""Every rule's check. Importing this package registers all of them (see ``base.REGISTRY``)."""

from __future__ import annotations

import functools
import importlib
import pkgutil

from fuzzoff.checks.base import REGISTRY, Check, CheckContext


@functools.cache
def load_all() -> tuple[type[Check], ...]:
    """Import every module of this package once, so that each check registers itself."""
    for module in pkgutil.iter_modules(__path__):
        if module.name != "base" and not module.name.startswith("_"):
            importlib.import_module(f"{__name__}.{module.name}")
    return tuple(REGISTRY)


__all__ = ["REGISTRY", "Check", "CheckContext", "load_all"]
