"""Words a user can follow (issue 30 item 5): every place fuzzoff cites its reasoning names a
section of docs/gate.md that exists, never a section number of a document outside the
repository, and ``fuzzoff rule`` keeps rule names whole in an 80-column terminal."""

from __future__ import annotations

import json
import re

import pytest

from fuzzoff.catalog import load_catalog
from fuzzoff.fuzz.hazards import Hazard
from fuzzoff.gate.sections import ANCHORS, anchor, cite
from tests.helpers import ROOT, run_cli

GATE_DOC = (ROOT / "docs" / "gate.md").read_text(encoding="utf-8")
DOC_ANCHORS = set(re.findall(r'<a id="([a-z0-9-]+)"></a>', GATE_DOC))
RECORDINGS = [
    "corpora/tlog/stream_lost_in_offboard.tlog",
    "corpora/tlog/mission_on_rejected_switch_1_17_0.tlog",
    "corpora/tlog/arm_between_acks_1_16_2.tlog",
]


def test_every_section_the_code_cites_is_an_anchor_of_gate_md() -> None:
    assert set(ANCHORS.values()) <= DOC_ANCHORS
    assert anchor("5.1") == "loss" and anchor("2.1.3") == "check-timing"
    assert anchor("13a") == "seen-on-px4" and cite("6.3") == "gate.md#receiver"


@pytest.mark.parametrize("recording", RECORDINGS)
def test_gate_cites_gate_md_sections(recording: str) -> None:
    text = run_cli(["gate", recording], cwd=ROOT)
    assert text.returncode in (0, 1), text.stderr
    header = next(line for line in text.stdout.splitlines() if "time s" in line)
    assert " see " in header and " spec " not in header
    rows = [
        line.split() for line in text.stdout.splitlines() if re.match(r"^\s+\d+\.\d{3}  \S", line)
    ]
    cited = {row[2] for row in rows if row[2].startswith("gate.md#")}
    assert cited and {c.removeprefix("gate.md#") for c in cited} <= DOC_ANCHORS
    # no row shows a bare section number where the citation stands
    assert not [row for row in rows if re.fullmatch(r"\d+(\.\d+)*[a-z]?", row[2])]
    data = json.loads(run_cli(["gate", recording, "--format", "json"], cwd=ROOT).stdout)
    model = [r for f in data["files"] for v in f["vehicles"] for r in v["timeline"]]
    model = [r for r in model if r["source"] == "model"]
    assert model and all("spec" not in r for r in model)
    assert all(r["see"] and r["see"].removeprefix("docs/gate.md#") in DOC_ANCHORS for r in model)


def test_fuzz_hazards_cite_gate_md() -> None:
    hazard = Hazard(t=9.1, kind="failsafe", message="POSCTL", spec="5.1", end=9.2)
    assert hazard.describe() == "failsafe at 9.100 s (POSCTL; gate.md#loss)"
    assert "gate spec" not in hazard.describe()


def test_rule_names_stay_whole_in_80_columns(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COLUMNS", "80")
    monkeypatch.setenv("NO_COLOR", "1")
    out = run_cli(["rule"], cwd=ROOT).stdout
    lines = out.splitlines()
    assert all(len(line.rstrip()) <= 80 for line in lines)
    names = {r.name for r in load_catalog().values()}
    shown = {line.split("|")[1].strip() for line in lines[2:] if line.split("|")[0].strip()}
    assert shown == names
