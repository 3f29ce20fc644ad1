"""Recordings named by fsspec URLs (``s3://``, ``gs://``, ``az://``, ``https://``, globs).

The client lists what a URL names (``expand``); the worker that lints a recording fetches it
into its own temporary folder (``fetched``), where every reader finds the local file it needs
(rosbags opens sqlite3 bags and bag folders by path, pyulog and the tlog framer seek), and the
folder is removed when the lint is done. Credentials come from the environment each backend
reads (``AWS_*``, ``GOOGLE_APPLICATION_CREDENTIALS``, ``AZURE_STORAGE_*``), never from
fuzzoff's configuration.
"""

from __future__ import annotations

import hashlib
import posixpath
import re
import stat
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from fuzzoff.config import ConfigError
from fuzzoff.fleet import is_url
from fuzzoff.formats import RECORDING_SUFFIXES

_GLOB = re.compile(r"[*?\[]")
CHUNK = 1 << 20
"""Bytes read at a time when hashing (memory stays flat whatever the recording's size)."""


class FetchError(Exception):
    """A URL could not be fetched; ``str()`` says why, in one line."""


def _filesystem(url: str) -> tuple[Any, str]:
    """The fsspec filesystem and the path within it; a missing backend is one usage line."""
    import fsspec

    try:
        fs, path = fsspec.core.url_to_fs(url)
    except ImportError as exc:  # fsspec names the package to install (s3fs, gcsfs, adlfs)
        raise ConfigError(f"{url}: {_reason(exc)}") from None
    except ValueError as exc:  # "Protocol not known"
        raise ConfigError(f"{url}: {_reason(exc)}") from None
    return fs, path


def _reason(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


def expand(url: str) -> list[str]:
    """The recordings a URL names, as URLs, in name order: a file as given; a glob's matches;
    a folder searched for recordings (files with a recording's suffix, in any case, and ROS 2
    bag folders, which hold a metadata.yaml). Nothing found is a usage error, as for a local
    folder: a nightly job pointed at an empty prefix must not pass."""
    fs, path = _filesystem(url)
    try:
        if _GLOB.search(path) and "http" not in fs.protocol:
            names = sorted(str(p) for p in fs.glob(path))
            found = [_as_url(fs, url, p) for p in names if not fs.isdir(p)]
            found += [u for p in names if fs.isdir(p) for u in _search(fs, url, p)]
        elif fs.isdir(path):
            found = _search(fs, url, path)
        elif fs.exists(path):
            found = [url]
        else:
            raise ConfigError(f"no such recording or folder: {url}")
    except ConfigError:
        raise
    except Exception as exc:  # a backend's own error (network, permissions): one line
        raise ConfigError(f"cannot list {url}: {_reason(exc)}") from None
    if not found:
        suffixes = ", ".join(RECORDING_SUFFIXES)
        raise ConfigError(f"no recordings in {url} (searched for {suffixes} and bag folders)")
    return found


def _search(fs: Any, url: str, top: str) -> list[str]:
    files = sorted(str(p) for p in fs.find(top))
    bags = sorted({posixpath.dirname(p) for p in files if posixpath.basename(p) == "metadata.yaml"})
    found = [_as_url(fs, url, b) for b in bags]
    for p in files:
        in_bag = any(p.startswith(b.rstrip("/") + "/") for b in bags)
        if not in_bag and posixpath.splitext(p)[1].lower() in RECORDING_SUFFIXES:
            found.append(_as_url(fs, url, p))
    return sorted(found)


def _as_url(fs: Any, given: str, path: str) -> str:
    if is_url(path):  # HTTP paths are URLs already
        return path
    full: str = fs.unstrip_protocol(path)
    return full if is_url(given) else path


def worker_tmp() -> str | None:
    """The Dask worker's own folder for temporary files, when running in one (else the
    system's temporary folder)."""
    try:
        from distributed import get_worker

        return str(get_worker().local_directory)
    except (ImportError, ValueError):
        return None


@contextmanager
def fetched(url: str) -> Iterator[Path]:
    """The recording at ``url`` as a local file or bag folder in a temporary folder, removed
    afterwards (also when the lint fails)."""
    with tempfile.TemporaryDirectory(prefix="fuzzoff-fetch-", dir=worker_tmp()) as tmp:
        try:
            fs, path = _filesystem(url)
        except ConfigError as exc:
            raise FetchError(str(exc).removeprefix(f"{url}: ")) from None
        name = posixpath.basename(path.rstrip("/")) or "recording"
        local = Path(tmp) / name
        try:
            if fs.isdir(path):
                _get_folder(fs, path, local)
            else:
                fs.get_file(path, str(local))
        except FileNotFoundError:
            raise FetchError("cannot fetch: not found") from None
        except Exception as exc:  # the backend's own error (network, permissions, ...)
            raise FetchError(f"cannot fetch: {_reason(exc)}") from None
        yield local


def _get_folder(fs: Any, path: str, local: Path) -> None:
    """A bag folder, file by file (``fs.get`` of a folder differs between backends: HTTP
    lists a folder's links, object stores list a prefix)."""
    top = path.rstrip("/")
    for remote in sorted(str(p) for p in fs.find(top)):
        rel = remote[len(top) :].lstrip("/")
        if not rel or ".." in rel.split("/"):
            continue
        dest = local.joinpath(*rel.split("/"))
        dest.parent.mkdir(parents=True, exist_ok=True)
        fs.get_file(remote, str(dest))
    local.mkdir(exist_ok=True)


def content_hash(path: Path) -> tuple[str | None, int | None]:
    """SHA-256 of a recording's bytes and its size; for a bag folder, of every file in it in
    name order with its name (so a renamed or moved recording keeps its hash). None for what
    cannot be read as a file or folder (a pipe would make the hash wait for a writer): the
    lint says why."""
    try:
        return _hash(path)
    except OSError:
        return None, None


def _hash(path: Path) -> tuple[str | None, int | None]:
    digest = hashlib.sha256()
    size = 0
    mode = path.stat().st_mode
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        return None, None
    if stat.S_ISDIR(mode):
        for f in sorted(p for p in path.rglob("*") if p.is_file()):
            rel = f.relative_to(path).as_posix().encode("utf-8", "surrogateescape")
            digest.update(rel + b"\0")
            size += _feed(digest, f)
    else:
        size = _feed(digest, path)
    return digest.hexdigest(), size


def _feed(digest: Any, path: Path) -> int:
    size = 0
    with path.open("rb") as fh:
        while chunk := fh.read(CHUNK):
            digest.update(chunk)
            size += len(chunk)
    return size
