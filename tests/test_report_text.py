"""Bidi controls from a recording never reach a report raw (issue 19 item 5, Trojan Source).

A vehicle namespace with U+202E (right-to-left override) and U+2066 (left-to-right isolate) in
a real MCAP: JSON, SARIF, JUnit, HTML and the terminal hold no such character; JSON and SARIF
give the same strings back to a parser; the terminal writes ``\\u202e``, not ``\\x202e`` (which
reads as ``\\x20`` and "2e")."""

from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path

import pytest

from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.report.sanitize import escape_bidi, printable
from tests.helpers import CORPORA, run_cli

NAMESPACE = "/px4_\u202e1\u2066x"
REORDERING = "\u061c\u200e\u200f\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069"


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    sys.path.insert(0, str(CORPORA / "mcap"))
    from flights import Flight  # corpora/mcap/flights.py: the MCAP corpus's flights

    flight = Flight(gaps=[(6.0, 9.5)], lost_mode_at=7.0)
    events = [dataclasses.replace(e, vehicle=NAMESPACE) for e in flight.events()]
    path = tmp_path_factory.mktemp("bidi") / "flight.mcap"
    return write_mcap(path, events, release="1.15")


@pytest.mark.parametrize("form", ["json", "sarif", "junit", "html", "terminal"])
def test_no_report_holds_a_raw_bidi_control(form: str, recording: Path) -> None:
    result = run_cli(["lint", str(recording), "--format", form])
    assert "OFB101" in result.stdout  # the findings name the vehicle
    assert not set(REORDERING) & set(result.stdout)


def test_json_and_sarif_give_the_strings_back(recording: Path) -> None:
    (report,) = json.loads(run_cli(["lint", str(recording), "--format", "json"]).stdout)["files"]
    assert {f["vehicle"] for f in report["findings"] if f.get("vehicle")} == {NAMESPACE}
    sarif = json.loads(run_cli(["lint", str(recording), "--format", "sarif"]).stdout)
    texts = [r["message"]["text"] for r in sarif["runs"][0]["results"]]
    # SARIF messages are shown by code-scanning views: written out there, as on the terminal.
    assert any("\\u202e" in text for text in texts)


def test_the_terminal_writes_u_escapes(recording: Path) -> None:
    out = run_cli(["lint", str(recording)]).stdout
    assert "/px4_\\u202e1\\u2066x" in out and "\\x202e" not in out
    assert printable("\x1b\u202e") == "\\x1b\\u202e"


def test_escaped_json_parses_to_the_same_text() -> None:
    text = json.dumps({"a": f"x{REORDERING}\u2028y \\u202e"}, ensure_ascii=False)
    safe = escape_bidi(text)
    assert not set(REORDERING + "\u2028") & set(safe)
    assert json.loads(safe) == json.loads(text)
