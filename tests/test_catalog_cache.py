"""The catalog's JSON copy in the user's cache folder: never stale, never in the way."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from fuzzoff.catalog import Rule, _catalog_dir, cache_file, load_catalog, read_catalog


@pytest.fixture
def pages(tmp_path: Path) -> Path:
    directory = tmp_path / "rules"
    directory.mkdir()
    for page in _catalog_dir().glob("OFB*.toml"):
        shutil.copy2(page, directory / page.name)
    return directory


@pytest.fixture
def cache(tmp_path: Path) -> Path:
    return tmp_path / "cache" / "fuzzoff" / "catalog.json"


def same(a: dict[str, Rule], b: dict[str, Rule]) -> bool:
    """Equal catalogs (by ``repr``: a rule's example may hold NaN, which is not equal to itself)."""
    return repr(a) == repr(b)


def test_the_copy_gives_the_catalog_the_pages_give(pages: Path, cache: Path) -> None:
    parsed = read_catalog(pages, cache)
    assert cache.is_file()
    assert same(read_catalog(pages, cache), parsed)
    assert same(parsed, load_catalog())


def test_the_copy_is_what_a_second_process_reads(pages: Path, cache: Path) -> None:
    read_catalog(pages, cache)
    copy = json.loads(cache.read_text())
    copy["pages"]["OFB101.toml"]["name"] = "from-the-copy"
    cache.write_text(json.dumps(copy))
    assert read_catalog(pages, cache)["OFB101"].name == "from-the-copy"


def test_an_edited_page_is_read_again(pages: Path, cache: Path) -> None:
    old = read_catalog(pages, cache)["OFB101"].name
    page = pages / "OFB101.toml"
    page.write_text(page.read_text().replace(f'name = "{old}"', 'name = "renamed-rule"', 1))
    assert read_catalog(pages, cache)["OFB101"].name == "renamed-rule"
    assert json.loads(cache.read_text())["pages"]["OFB101.toml"]["name"] == "renamed-rule"


def test_a_damaged_copy_is_replaced(pages: Path, cache: Path) -> None:
    cache.parent.mkdir(parents=True)
    cache.write_bytes(b"\x00{not json")
    assert same(read_catalog(pages, cache), load_catalog())
    assert json.loads(cache.read_text())["pages"]


def test_no_place_for_a_copy_only_costs_the_parse(pages: Path, cache: Path) -> None:
    cache.parent.parent.mkdir(parents=True)
    cache.parent.write_text("a file where the folder would be")
    assert same(read_catalog(pages, cache), load_catalog())


def test_the_copy_lives_in_the_users_cache_folder(
    pages: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    where = cache_file(pages)
    assert where is not None and where.parent == tmp_path / "xdg" / "fuzzoff"
    assert where != cache_file(_catalog_dir())  # one copy per catalog folder
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert cache_file(pages) == tmp_path / "home" / ".cache" / "fuzzoff" / where.name
