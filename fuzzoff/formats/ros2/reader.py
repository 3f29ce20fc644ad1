"""Reading ROS 2 data files through rosbags, the storage chosen by content (``ros2.storage``)."""

from __future__ import annotations

from pathlib import Path

from rosbags.rosbag2 import Reader

from fuzzoff.formats.ros2.storage import SUFFIX, Storage, storage_of


class StorageReader(Reader):
    """rosbags' ``Reader`` with a data file's storage chosen by its content (a bag folder is
    read as rosbags reads it: its metadata.yaml names the storage)."""

    def __init__(self, path: Path, storage: Storage | None = None) -> None:
        if path.is_file():
            storage = storage or storage_of(path)
            if storage is not None:
                plugin = Reader.STORAGE_PLUGINS[SUFFIX[storage]]
                self.STORAGE_PLUGINS = {path.suffix: plugin}
        super().__init__(path)
