"""Which storage a ROS 2 data file is, from its content, never its name (issue 26 item 3).

rosbags chooses a data file's storage from its suffix (``.db3``, ``.mcap``, exactly), so an
intact MCAP named ``FLIGHT.MCAP``, ``flight.mcap.active`` or ``flight`` was read as a damaged
database. The registry detects a recording by its first bytes; the readers ask the same bytes
which storage each data file is, and open it with rosbags' reader of that storage
(``ros2.reader.StorageReader``). Importing this module loads no reading library.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

SQLITE_MAGIC = b"SQLite format 3\x00"
MCAP_MAGIC = b"\x89MCAP"

Storage = Literal["sqlite3", "mcap"]
"""rosbag2's names for its storage plugins (metadata.yaml's ``storage_identifier``)."""
SUFFIX: dict[Storage, str] = {"sqlite3": ".db3", "mcap": ".mcap"}
"""The suffix rosbag2 gives each storage's data files, which rosbags' reader goes by."""
_BY_SUFFIX: dict[str, Storage] = {suffix: storage for storage, suffix in SUFFIX.items()}


def storage_from_head(head: bytes) -> Storage | None:
    """The storage a file's first bytes say, or None."""
    if head.startswith(SQLITE_MAGIC):
        return "sqlite3"
    if head.startswith(MCAP_MAGIC):
        return "mcap"
    return None


def storage_of(path: Path) -> Storage | None:
    """The storage of the data file at ``path``: its first bytes say it; where they say nothing
    (damage at the start), its name (``.db3``, ``.mcap``, in any case, before an ``.active``);
    None when neither does, or the file cannot be read."""
    try:
        with path.open("rb") as fh:
            head = fh.read(len(SQLITE_MAGIC))
    except OSError:
        head = b""
    return storage_from_head(head) or storage_by_name(path)


def storage_by_name(path: Path) -> Storage | None:
    """The storage a file's name suggests (``x.DB3``, ``x.mcap.active``), or None."""
    suffixes = [s.lower() for s in path.suffixes]
    if suffixes and suffixes[-1] == ".active":
        suffixes.pop()
    return _BY_SUFFIX.get(suffixes[-1]) if suffixes else None


def data_files(folder: Path) -> list[Path]:
    """A bag folder's data files, in name order: every regular file whose content (or, where
    damage hides it, whose name) is a storage's, whatever the name."""
    return sorted(
        path
        for path in folder.iterdir()
        if path.name != "metadata.yaml"
        and not path.name.startswith(".")
        and path.is_file()
        and storage_of(path) is not None
    )
