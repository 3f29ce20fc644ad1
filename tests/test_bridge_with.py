"""``fuzzoff lint BAG --with ULOG`` on real flights over PX4's ROS 2 bridge (issue 28 item 3).

The recordings are corpora/ros2bridge's: px4_ros_com's example flown on the 1.16.2 and 1.18
head SITL bundles, the companion's bag beside PX4's own ULog of the same flight. On a clean
flight every message sent after the bridge matched the writers reached PX4, within
milliseconds; on the agent restart (PX4 #26022) PX4 received nothing for about 10 s while the
companion published on, flagged the offboard signal lost, and the companion heard of it only
when the bridge came back.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from tests.helpers import run_cli
from tests.test_ci_formats import errors, lint_report_validator

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT / "corpora" / "ros2bridge"


def lint_with(bag: str, ulog: str, *more: str) -> tuple[int, dict[str, Any], str]:
    out = run_cli(
        ["lint", str(CORPUS / bag), *more, "--with", str(CORPUS / ulog), "--format", "json"]
    )
    return out.returncode, json.loads(out.stdout) if out.stdout else {}, out.stderr


def topic(delivery: dict[str, Any], name: str) -> dict[str, Any]:
    (found,) = [t for t in delivery["topics"] if t["topic"].startswith(name)]
    return found


@pytest.mark.parametrize(
    "flight", ["example-1.16.2-ros2", "example-1.18.0-beta1-head", "example_stops-1.16.2-ros2"]
)
def test_a_clean_flight_delivered_everything_within_milliseconds(flight: str) -> None:
    status, report, _ = lint_with(f"{flight}-mcap", f"{flight}.ulg")
    assert status == (1 if "stops" in flight else 0)  # OFB103 there: the stream stopped
    (file,) = report["files"]
    assert not [f for f in file["findings"] if f["code"] == "OFB108"]
    delivery = file["delivery"]
    assert delivery["clock"]["source"] == "px4_outputs"
    assert delivery["clock"]["residual_ms"] < 10
    for name in ("/fmu/in/offboard_control_mode", "/fmu/in/vehicle_command"):
        sent = topic(delivery, name)
        assert sent["undelivered"] == 0
        assert sent["logged_by_px4"] > 0
        assert sent["latency_ms"]["median"] < 20
    assert all(
        c["seen_after_s"] is not None and c["seen_after_s"] < 0.5 for c in delivery["px4_changes"]
    )


@pytest.mark.parametrize(
    ("flight", "storage", "failsafe"),
    [
        ("example_agent_restart-1.16.2-ros2", "mcap", "POSCTL"),
        ("example_agent_restart-1.18.0-beta1-head", "sqlite3", "AUTO_RTL"),
    ],
)
def test_the_agent_restart_gives_the_undelivered_stream_and_px4s_loss(
    flight: str, storage: str, failsafe: str
) -> None:
    status, report, _ = lint_with(f"{flight}-{storage}", f"{flight}.ulg")
    assert status == 1
    (file,) = report["files"]
    (finding,) = [f for f in file["findings"] if f["code"] == "OFB108"]
    assert finding["severity"] == "error"
    assert 6.0 < finding["time_s"] < 7.0 and finding["end_s"] - finding["time_s"] > 10
    assert "flagged the offboard signal lost" in finding["message"]
    assert "the bridge itself was down" in finding["message"]
    delivery = file["delivery"]
    assert topic(delivery, "/fmu/in/offboard_control_mode")["undelivered"] > 100
    lost = [c for c in delivery["px4_changes"] if c["state"] == "offboard signal lost"]
    # the companion heard of it when PX4 came back 9.6 s later (1.16.2), or not before its
    # recording ended (the 1.18 head, whose simulation ran at 0.76 of real time)
    assert lost and (lost[0]["seen_after_s"] is None or lost[0]["seen_after_s"] > 9)
    assert any(failsafe in c["state"] and "failsafe" in c["state"] for c in delivery["px4_changes"])
    # PX4 synchronized again with the new agent: its logged line; on the 1.18 head its
    # timesync_status shows the new offset 6 s before that line (17.7 s), a sync of its own
    first, *new_agent = (s["offset_us"] for s in delivery["clock"]["time_syncs"])
    assert new_agent and all(abs(o - first) > 100_000 for o in new_agent)
    assert all(abs(o - new_agent[-1]) < 50_000 for o in new_agent)
    assert delivery["px4_signal_lost"]
    assert not errors(lint_report_validator(), report)


def test_the_terminal_shows_what_was_sent_and_never_received() -> None:
    flight = "example_agent_restart-1.16.2-ros2"
    out = run_cli(["lint", str(CORPUS / f"{flight}-mcap"), "--with", str(CORPUS / f"{flight}.ulg")])
    assert out.returncode == 1
    assert "OFB108" in out.stdout
    assert "/fmu/in/offboard_control_mode: 170 sent" in out.stdout
    assert "106 not received" in out.stdout
    assert "offboard signal lost: seen 9.59 s later" in out.stdout


def test_an_arm_px4_never_received_is_named() -> None:
    flight = "example_arm_lost-1.16.2-ros2"
    status, report, _ = lint_with(f"{flight}-mcap", f"{flight}.ulg")
    assert status == 1
    (finding,) = [f for f in report["files"][0]["findings"] if f["code"] == "OFB108"]
    assert finding["summary"] == "a command PX4 never received"
    assert topic(report["files"][0]["delivery"], "/fmu/in/vehicle_command")["undelivered"] == 1


def test_bag_and_ulog_in_one_lint() -> None:
    flight = "example-1.16.2-ros2"
    status, report, _ = lint_with(
        f"{flight}-sqlite3", f"{flight}.ulg", str(CORPUS / f"{flight}.ulg")
    )
    assert status == 0
    assert [("delivery" in f) for f in report["files"]] == [True, False]


@pytest.mark.parametrize(
    ("bag", "ulog", "says"),
    [
        ("example-1.16.2-ros2-mcap", "example_stops-1.16.2-ros2.ulg", "are not the same flight"),
        ("example_in_only-1.16.2-ros2-mcap", "example-1.16.2-ros2.ulg", "are not the same flight"),
        ("example-1.16.2-ros2-mcap", "../sitl/acceleration_only-1.14.4.ulg", "no time sync"),
        ("example-1.16.2-ros2.ulg", "example-1.16.2-ros2.ulg", "one ROS 2 bag folder"),
    ],
)
def test_files_of_two_flights_are_refused_in_one_line(bag: str, ulog: str, says: str) -> None:
    status, report, stderr = lint_with(bag, ulog)
    assert status == 2 and not report
    assert says in stderr
    assert len(stderr.strip().splitlines()) == 1
    assert "Traceback" not in stderr


def test_the_gate_model_on_a_bridge_bag_agrees_with_px4_where_the_bridge_delivered() -> None:
    from fuzzoff.sitl.ros2.verdict import compare

    clean = compare(CORPUS / "example-1.16.2-ros2-mcap", "1.16", CORPUS / "example-1.16.2-ros2.ulg")
    assert [(i.what, i.agree) for i in clean.items] == [
        ("switch to OFFBOARD", True),
        ("arm", True),
    ]
    flight = "example_agent_restart-1.16.2-ros2"
    restart = compare(CORPUS / f"{flight}-sqlite3", "1.16", CORPUS / f"{flight}.ulg")
    # the model sees the stream as sent: PX4's loss is the bridge's (OFB108), not the stream's
    assert [(i.what, i.agree) for i in restart.items if not i.agree] == [("offboard loss", False)]


def test_a_log_started_after_the_bridge_connected_is_aligned_by_timesync_status(
    tmp_path: Path,
) -> None:
    """Without PX4's "synchronized with time offset" line (a log from arming), the client's
    ``timesync_status`` gives the offsets."""
    from pyulog import ULog

    flight = "example_agent_restart-1.18.0-beta1-head"
    log = ULog(str(CORPUS / f"{flight}.ulg"))
    log._logged_messages = []  # pyulog writes back what it holds
    log.write_ulog(str(tmp_path / "from_arming.ulg"))
    log_file = str(tmp_path / "from_arming.ulg")
    out = run_cli(["lint", str(CORPUS / f"{flight}-mcap"), "--with", log_file, "--format", "json"])
    assert out.returncode == 1, out.stderr
    (file,) = json.loads(out.stdout)["files"]
    (finding,) = [f for f in file["findings"] if f["code"] == "OFB108"]
    assert 6.0 < finding["time_s"] < 7.0
    assert file["delivery"]["clock"]["source"] == "px4_outputs"


def test_the_html_report_shows_what_was_sent_against_what_was_received(tmp_path: Path) -> None:
    """The agent restart in ``--format html``: per topic sent, in PX4's log, never received
    and latency; PX4's loss the companion saw 9.6 s late; every recording text escaped (a
    bag folder named with markup)."""
    import shutil

    flight = "example_agent_restart-1.16.2-ros2"
    bag = tmp_path / "<img src=x>&flight-mcap"
    shutil.copytree(CORPUS / f"{flight}-mcap", bag)
    page = tmp_path / "report.html"
    args = ["lint", str(bag), "--with", str(CORPUS / f"{flight}.ulg")]
    out = run_cli([*args, "--format", "html", "--output", str(page)])
    assert out.returncode == 1, out.stderr
    html = page.read_text()
    section = html[html.index("<h3>Sent against received</h3>") :]
    section = section[: section.index("</section>")]
    assert f"With PX4's ULog {CORPUS / flight}.ulg: PX4's clock runs at 0.982 of the host's" in (
        section
    )
    assert (
        "PX4 flagged the offboard signal lost once; of those losses the companion never saw 0"
        " and saw 1 only 1 s or more later. 0 of PX4's 6 status changes never reached it."
    ) in section
    assert (
        '<tr class="undelivered"><td>/fmu/in/offboard_control_mode</td><td>to PX4</td>'
        "<td>170</td><td>58</td><td>106</td><td>4.9 ms</td><td>71.6 ms</td><td></td></tr>"
    ) in section
    assert (
        "<tr><td>/fmu/in/vehicle_command</td><td>to PX4</td><td>2</td><td>2</td><td>0</td>"
        "<td>5.5 ms</td><td>5.5 ms</td><td></td></tr>"
    ) in section
    assert "none reached the companion 6.23-17.32 s" in section
    assert (
        "<tr><td>13.59 s</td><td>7.55 s</td><td>offboard signal lost</td><td>9.59 s later</td></tr>"
    ) in section
    assert "<img src=x>" not in html
    assert "&lt;img src=x&gt;&amp;flight-mcap" in html


def test_a_flight_without_the_bridges_time_sync_is_refused_in_one_line_saying_so() -> None:
    """PX4 1.16.2 with UXRCE_DDS_SYNCT 0 (the corpus example's bag replayed over the bridge,
    ``sitl replay --transport ros2 --param UXRCE_DDS_SYNCT=0``): PX4 logs no time sync and its
    outputs carry its own boot time, so the bag's host times cannot be put on PX4's clock.
    One line, exit 2, naming the parameter (not 'it was not on the bridge')."""
    folder = CORPUS / "nosync"
    bag, ulog = (
        folder / "example_synct0-1.16.2-ros2-mcap",
        folder / "example_synct0-1.16.2-ros2.ulg",
    )
    out = run_cli(["lint", str(bag), "--with", str(ulog), "--format", "json"])
    assert out.returncode == 2
    assert not out.stdout
    assert out.stderr.strip().splitlines() == [
        f"error: {ulog}: PX4 ran its ROS 2 bridge without time sync (UXRCE_DDS_SYNCT 0): the"
        " bag's times, on the host's clock, cannot be put on PX4's; nothing compared (set"
        " UXRCE_DDS_SYNCT 1 to compare a flight)"
    ]
