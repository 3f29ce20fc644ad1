"""One entry per recording format: how it is detected, read and written, and what it carries.

Each format package (``fuzzoff/formats/<name>/__init__.py``) declares its ``FORMAT``; the
registry (``fuzzoff.formats.registry``) lists them once for lint, fuzz and the tools. Readers and
writers are named, not imported: a run loads only the libraries of the formats it meets.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fuzzoff.events import Event
from fuzzoff.lean_dataclass import dataclass

if TYPE_CHECKING:
    from fuzzoff.recording import Source

Transport = str
"""How a stream reaches PX4, as the fuzz campaign names it: ``ros2``, ``mavlink``, ``mavros``."""


def _no_options(px4: str | None) -> Mapping[str, Any]:
    return {}


@dataclass(frozen=True, slots=True)
class Format:
    name: str
    """The package's name, and the name ``fuzz`` writes it under (``rosbag2``)."""
    reader: str
    """``module:class`` of the reader (a ``Source``)."""
    writer: str
    """``module:function`` of the writer: ``write(path, events, **options) -> Path``."""
    clock: str
    """``module:function`` giving when the recording started on the wall clock (UNIX seconds),
    or None where it does not say (the fleet table's weeks)."""
    detect_file: Callable[[Path, bytes], str | None]
    """The format name a file's first 32 bytes (and its place) say, or None: the name a
    recording is reported under (``rosbag2-sqlite3``), which may differ from ``name``."""
    names: tuple[str, ...]
    """Every name ``detect_file``/``detect_folder`` give, each read by ``reader``."""
    suffixes: tuple[str, ...]
    """File names a folder search takes (lower case); the first is the usual one."""
    written_suffix: str
    """What ``writer`` is given as a file name's suffix (``""``: the writer makes a folder)."""
    fallback: bool = False
    """Detected only where no other format claims the file (a tlog has no header: its likely
    first packet could be any file's bytes)."""
    transports: tuple[Transport, ...] = ()
    """The streams whose messages this format records as sent (empty for a vehicle's log)."""
    is_folder: Callable[[Path, tuple[str, ...]], bool] | None = None
    """Is a folder one recording of this format (a ROS 2 bag), not a folder of recordings to
    search? Given the folder and the file names a search takes (``RECORDING_SUFFIXES``)."""
    detect_folder: Callable[[Path], str] | None = None
    """The format name of a folder ``is_folder`` claims (raises ``SourceError`` when it is not
    readable as one)."""
    writer_options: Callable[[str | None], Mapping[str, Any]] = _no_options
    """The writer's options for a PX4 release or profile name (the message definitions a
    ROS 2 recording embeds, the layouts a ULog declares)."""

    def open(self, path: Path, name: str | None = None) -> Source:
        """A reader for ``path`` (not yet opened), reported as ``name`` (default ``self.name``)."""
        cls: type[Source] = _load(self.reader)
        source = cls(path)
        source.format = name or self.name
        return source

    def write(self, path: Path, events: Iterable[Event], px4: str | None = None) -> Path:
        """``events`` written at ``path`` as PX4 ``px4`` would have them recorded."""
        function: Callable[..., Path] = _load(self.writer)
        return function(path, events, **self.writer_options(px4))

    def start_s(self, path: Path) -> float | None:
        """When the recording at ``path`` started on the wall clock, where it says."""
        function: Callable[[Path], float | None] = _load(self.clock)
        return function(path)


def _load(target: str) -> Any:
    module_name, _, attribute = target.partition(":")
    return getattr(importlib.import_module(module_name), attribute)
