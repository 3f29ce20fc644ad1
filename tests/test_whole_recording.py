"""What a recording as a whole says: one OFB002 line for the rules it cannot show, after what was
found (terminal, HTML, JSON), and one OFB005 line when offboard was never used in it."""

from __future__ import annotations

import json
import re
from pathlib import Path

from fuzzoff.config import Settings
from fuzzoff.engine import lint_file, run_events
from fuzzoff.events import Command, VehicleStatus
from fuzzoff.findings import Report
from fuzzoff.profiles import Profile
from fuzzoff.recording import RecordingInfo
from fuzzoff.report.html import render
from tests.helpers import CORPORA, run_cli
from tests.streams import OFFBOARD, POSCTL, codes, every, lint_events, ocm, status, switch

# a real PX4 1.16.2 SITL ULog: a switch refused (two errors) and five rules it cannot show
REFUSED_ULOG = CORPORA / "sitl" / "enu_frame-1.16.2.ulg"
# PX4's own log of a mission: no offboard at all
MISSION_ULOG = CORPORA / "ulog" / "auto_mission.ulg"


def test_a_ulog_says_once_which_rules_it_cannot_show_and_what_each_needs() -> None:
    found = lint_file(REFUSED_ULOG).findings
    (note,) = codes(found, "OFB002")
    for code in ("OFB105", "OFB203", "OFB302"):
        assert code in note.short
        assert re.search(rf"{code} \([a-z-]+\) needs the \w", note.message), note.message
    assert note.message.startswith("3 rules cannot be checked on this recording: ")


def test_what_cannot_be_checked_comes_after_the_errors_in_every_output() -> None:
    json_out = json.loads(run_cli(["lint", str(REFUSED_ULOG), "--format", "json"]).stdout)
    order = [f["code"] for f in json_out["files"][0]["findings"]]
    assert order[-1] == "OFB002" and order.count("OFB002") == 1
    assert {"OFB102", "OFB201"} <= set(order[:-1])

    terminal = run_cli(["lint", str(REFUSED_ULOG)]).stdout.splitlines()
    lines = [i for i, line in enumerate(terminal) if re.search(r" OFB\d{3} ", line)]
    errors = [i for i in lines if " error " in terminal[i]]
    (not_checkable,) = [i for i in lines if " OFB002 " in terminal[i]]
    assert errors and not_checkable > max(errors)

    page = render(Report(files=[lint_file(REFUSED_ULOG)]), Settings())
    row = r'<tr id="finding-[^"]*" class="(\w+)"><td>[^<]*</td><td><a[^>]*>(OFB\d+)'
    rows = re.findall(row, page)
    assert rows[-1] == ("info", "OFB002")
    assert [sev for sev, _ in rows].index("error") < len(rows) - 1


def test_junit_skips_each_rule_with_its_own_reason() -> None:
    out = run_cli(["lint", str(REFUSED_ULOG), "--format", "junit"]).stdout
    skipped = dict(re.findall(r'name="(OFB\d+) [^"]*" time="0">\s*<skipped message="([^"]*)"', out))
    assert skipped["OFB105"].startswith("cannot be checked on this recording: OFB105 (")
    assert "OFB203" not in skipped["OFB105"] and "OFB302" in skipped["OFB302"]


def test_a_flight_without_offboard_says_so_in_one_line() -> None:
    found = lint_file(MISSION_ULOG).findings
    (note,) = codes(found, "OFB005")
    assert note.time_s is None and note.severity.label == "info"
    assert note.short.startswith("no offboard in this recording")
    assert "never in OFFBOARD" in note.message
    # a flight that used offboard has none
    assert codes(lint_file(REFUSED_ULOG).findings, "OFB005") == []


def test_a_stream_without_a_switch_says_when_it_began() -> None:
    events = [status(0.0, POSCTL), *ocm(every(2.0, 4.0, 0.1))]
    (note,) = codes(lint_events(events), "OFB005")
    assert "a stream was sent from 2.00 s" in note.message
    assert codes(lint_events([*events, status(4.0, OFFBOARD)]), "OFB005") == []
    # a requested switch is offboard use, refused or not
    assert codes(lint_events([*events, switch(3.0)]), "OFB005") == []


def test_several_vehicles_none_in_offboard_give_one_line_and_one_in_offboard_none() -> None:
    def vehicle(name: str, nav: int) -> list:
        return [VehicleStatus(t=t, vehicle=name, nav_state=nav, armed=True) for t in (0.0, 1.0)]

    info = RecordingInfo("two", "tlog", kinds={"vehicle_status"})
    profile = Profile(px4="1.16", vehicle="mc", px4_detected=True, vehicle_detected=True)
    events = sorted([*vehicle("1", POSCTL), *vehicle("2", POSCTL)], key=lambda e: e.t)
    found, _ = run_events(events, info, profile, Settings())
    (note,) = codes(found, "OFB005")
    assert "no vehicle was ever in OFFBOARD" in note.message
    events = sorted([*vehicle("1", POSCTL), *vehicle("2", OFFBOARD)], key=lambda e: e.t)
    found, _ = run_events(events, info, profile, Settings())
    assert codes(found, "OFB005") == []


def test_a_switch_seen_only_as_a_command_counts_without_a_recorded_mode() -> None:
    command = Command(t=1.0, command=176, params=(1.0, 6.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert codes(lint_events([*ocm(every(0.0, 2.0, 0.1)), command]), "OFB005") == []
    (note,) = codes(lint_events(ocm(every(0.0, 2.0, 0.1))), "OFB005")
    assert "the recording has no mode" in note.message


def test_on_a_damaged_recording_it_speaks_for_the_part_read(tmp_path: Path) -> None:
    cut = tmp_path / "cut.ulg"
    data = MISSION_ULOG.read_bytes()
    cut.write_bytes(data[: len(data) // 2])
    report = lint_file(cut)
    assert not report.complete
    (note,) = codes(report.findings, "OFB005")
    assert "(in the part that could be read)" in note.message
