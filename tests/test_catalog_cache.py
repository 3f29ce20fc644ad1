"""The catalog's JSON copy (``__pycache__/catalog.json``): never stale, never in the way."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from fuzzoff.catalog import CACHE, Rule, _catalog_dir, load_catalog, read_catalog


@pytest.fixture
def pages(tmp_path: Path) -> Path:
    directory = tmp_path / "rules"
    directory.mkdir()
    for page in _catalog_dir().glob("OFB*.toml"):
        shutil.copy2(page, directory / page.name)
    return directory


def same(a: dict[str, Rule], b: dict[str, Rule]) -> bool:
    """Equal catalogs (by ``repr``: a rule's example may hold NaN, which is not equal to itself)."""
    return repr(a) == repr(b)


def test_the_copy_gives_the_catalog_the_pages_give(pages: Path) -> None:
    parsed = read_catalog(pages)
    assert (pages / CACHE).is_file()
    assert same(read_catalog(pages), parsed)
    assert same(parsed, load_catalog())


def test_the_copy_is_what_a_second_process_reads(pages: Path) -> None:
    read_catalog(pages)
    copy = json.loads((pages / CACHE).read_text())
    copy["pages"]["OFB101.toml"]["name"] = "from-the-copy"
    (pages / CACHE).write_text(json.dumps(copy))
    assert read_catalog(pages)["OFB101"].name == "from-the-copy"


def test_an_edited_page_is_read_again(pages: Path) -> None:
    read_catalog(pages)
    page = pages / "OFB101.toml"
    text = page.read_text()
    old = read_catalog(pages)["OFB101"].name
    page.write_text(text.replace(f'name = "{old}"', 'name = "renamed-rule"', 1))
    assert read_catalog(pages)["OFB101"].name == "renamed-rule"
    assert json.loads((pages / CACHE).read_text())["pages"]["OFB101.toml"]["name"] == (
        "renamed-rule"
    )


def test_a_damaged_copy_is_replaced(pages: Path) -> None:
    (pages / CACHE).parent.mkdir()
    (pages / CACHE).write_bytes(b"\x00{not json")
    assert same(read_catalog(pages), load_catalog())
    assert json.loads((pages / CACHE).read_text())["pages"]


def test_no_place_for_a_copy_only_costs_the_parse(pages: Path) -> None:
    (pages / CACHE.parent).write_text("a file where the folder would be")
    assert same(read_catalog(pages), load_catalog())
    assert not (pages / CACHE).exists()
