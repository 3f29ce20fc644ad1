"""What a fuzz campaign knows about a rule comes from the rule's own page (``explains``,
``reports`` in ``rules/CODE.toml``): a page that changes them changes what the campaign accepts
as an explanation, and a page that names an outcome the gate model has not is refused."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from fuzzoff.catalog import HAZARD_KINDS, CatalogError, _catalog_dir, read_catalog
from fuzzoff.fuzz.hazards import EXPLAINED_BY, OUTCOME_RULE, explained_by


@pytest.fixture
def pages(tmp_path: Path) -> Path:
    directory = tmp_path / "rules"
    directory.mkdir()
    for page in _catalog_dir().glob("OFB*.toml"):
        shutil.copy2(page, directory / page.name)
    return directory


def _edit(pages: Path, code: str, old: str, new: str) -> None:
    page = pages / f"{code}.toml"
    text = page.read_text(encoding="utf-8")
    assert old in text
    page.write_text(text.replace(old, new, 1), encoding="utf-8")


def test_the_campaign_reads_each_outcome_s_rules_from_the_pages() -> None:
    assert set(EXPLAINED_BY) == set(HAZARD_KINDS)
    assert "OFB609" in EXPLAINED_BY["setpoint_dropped"]
    assert "OFB102" in EXPLAINED_BY["request_rejected"]
    assert "OFB102" not in EXPLAINED_BY["setpoint_dropped"]
    assert OUTCOME_RULE["failsafe"] == "OFB103" and OUTCOME_RULE["request_rejected"] == "OFB201"


def test_a_page_that_stops_explaining_an_outcome_leaves_it_to_the_others(pages: Path) -> None:
    _edit(pages, "OFB609", '"setpoint_dropped", ', "")
    explained, _ = explained_by(read_catalog(pages))
    assert "OFB609" not in explained["setpoint_dropped"]
    assert "OFB609" in explained["failsafe"]
    assert explained["setpoint_dropped"] == EXPLAINED_BY["setpoint_dropped"] - {"OFB609"}


def test_an_outcome_the_gate_model_has_not_is_refused(pages: Path) -> None:
    _edit(pages, "OFB104", '"controller"]', '"controllers"]')
    with pytest.raises(
        CatalogError, match=r"OFB104\.toml: explains: unknown outcome 'controllers'"
    ):
        read_catalog(pages)


def test_a_rule_reports_only_what_it_explains(pages: Path) -> None:
    _edit(
        pages,
        "OFB201",
        'reports = ["request_rejected"',
        'reports = ["failsafe", "request_rejected"',
    )
    with pytest.raises(CatalogError, match=r"OFB201\.toml: reports outcomes it does not explain"):
        read_catalog(pages)


def test_one_rule_reports_each_outcome(pages: Path) -> None:
    _edit(pages, "OFB101", 'summary = """', 'reports = ["failsafe"]\nsummary = """')
    with pytest.raises(CatalogError, match="failsafe is reported by OFB101 already"):
        explained_by(read_catalog(pages))
