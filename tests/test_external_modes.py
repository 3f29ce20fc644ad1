"""OFB209 on minimal streams, and the external-mode messages read back from written bags."""

from __future__ import annotations

from pathlib import Path

import pytest

from fuzzoff.events import (
    ArmingCheckReply,
    ArmingCheckRequest,
    Event,
    ExtComponentReply,
    ExtComponentRequest,
    ExtComponentUnregister,
    VehicleStatus,
)
from fuzzoff.findings import Severity
from fuzzoff.formats import open_source, px4_msgs
from fuzzoff.formats.mcap.writer import write_mcap
from fuzzoff.formats.rosbag2.writer import write_rosbag2
from tests.streams import codes, lint_events

MODE = 23


def _register(api: int = 1, reply_api: int = 1, success: bool = True) -> list[Event]:
    return [
        ExtComponentRequest(
            t=1.0, request_id=9, name="Orbit", api_version=api, arming_check=True, mode=True
        ),
        ExtComponentReply(
            t=1.05,
            request_id=9,
            name="Orbit",
            api_version=reply_api,
            success=success,
            arming_check_id=0 if success else -1,
            mode_id=MODE if success else -1,
        ),
    ]


def _checks(until: float, replies_until: float, mask: bool = False) -> list[Event]:
    out: list[Event] = []
    t, n, misses = 1.2, 0, 0
    while t < until:
        out.append(
            ArmingCheckRequest(
                t=t, request_id=n, registrations_mask=(1 if misses <= 3 else 0) if mask else None
            )
        )
        if t < replies_until:
            out.append(ArmingCheckReply(t=t + 0.01, request_id=n, registration_id=0))
        else:
            misses += 1
        t, n = round(t + 0.3, 6), n + 1
    return out


def _lint(events: list[Event], px4: str = "1.17") -> list[object]:
    status = [VehicleStatus(t=0.0, nav_state=2, armed=False)]
    return codes(lint_events(sorted([*status, *events], key=lambda e: e.t), px4=px4), "OFB209")


def test_a_refused_registration_is_an_error_with_the_reason() -> None:
    (found,) = _lint(_register(success=False))
    assert found.severity is Severity.ERROR and found.time_s == 1.05
    assert "refused" in found.summary and "Orbit" in found.message


def test_the_library_api_1_against_px4_118_api_2_is_an_error() -> None:
    (found,) = _lint([*_register(api=1, reply_api=2), *_checks(4.0, 0.0)], px4="1.18")
    assert found.severity is Severity.ERROR and found.time_s == 1.05
    assert "API version 1" in found.summary and "2" in found.summary


def test_a_request_never_answered_is_judged_by_the_release() -> None:
    request = _register(api=1)[:1]
    (found,) = _lint(request, px4="1.18")
    assert "PX4 speaks 2" in found.summary
    assert _lint(request, px4="1.17") == []


def test_matching_versions_and_answered_checks_give_nothing() -> None:
    assert _lint([*_register(), *_checks(6.0, 6.0)]) == []
    assert _lint([*_register(2, 2), *_checks(6.0, 6.0, mask=True)], px4="1.18") == []


def test_checks_unanswered_more_than_three_times_drop_the_mode() -> None:
    (found,) = _lint([*_register(), *_checks(6.0, 2.0)])
    # replies up to the request at 1.8 s; 2.1, 2.4, 2.7 and 3.0 unanswered: the fourth is one
    # too many
    assert found.time_s == 3.0 and "arming checks unanswered" in found.summary


def test_the_last_request_counts_when_px4_stops_asking() -> None:
    # PX4 stops sending requests once it dropped the registration: the fourth unanswered
    # request is the last one in the recording, closed by the recording going on
    events = [*_register(), *_checks(3.1, 2.0), VehicleStatus(t=4.5, nav_state=2, armed=False)]
    (found,) = _lint(events)
    assert found.time_s == 3.0
    assert _lint([*_register(), *_checks(3.1, 2.0)]) == []  # ends before the reply was due


def test_three_unanswered_requests_are_tolerated() -> None:
    events = [*_register(), *_checks(6.0, 6.0)]
    skipped = {2, 3, 4}  # three requests in a row without a reply, then replies again
    events = [
        e for e in events if not (isinstance(e, ArmingCheckReply) and e.request_id in skipped)
    ]
    assert _lint(events) == []


def test_px4_1_18_valid_registrations_mask_is_px4_own_verdict() -> None:
    # replies the recording shows, but PX4 took them as too late: it drops the registration
    events = [*_register(2, 2), *_checks(1.6, 1.6, mask=True)]
    events.append(ArmingCheckRequest(t=1.8, request_id=2, registrations_mask=0))
    (found,) = _lint(events, px4="1.18")
    assert found.time_s == 1.8 and "valid_registrations_mask" in found.message


def test_not_judged_without_the_companion_side() -> None:
    px4_side = [e for e in [*_register(), *_checks(6.0, 0.0)] if e.origin == "vehicle"]
    assert _lint(px4_side) == []


def test_a_mode_unregistered_while_flying_in_it_is_an_error() -> None:
    flying = [
        *_register(),
        *_checks(2.0, 2.0),
        VehicleStatus(t=1.5, nav_state=MODE, armed=True),
        ExtComponentUnregister(t=1.9, name="Orbit", arming_check_id=0, mode_id=MODE),
    ]
    (found,) = _lint(flying)
    assert found.time_s == 1.9 and "in flight" in found.summary
    landed = [*flying[:-2], VehicleStatus(t=1.5, nav_state=MODE, armed=False), flying[-1]]
    assert _lint(landed) == []


@pytest.mark.parametrize(("release", "suffix"), [("1.16", ""), ("main", "_v2")])
@pytest.mark.parametrize("storage", ["mcap", "sqlite3-without-definitions"])
def test_the_messages_read_back_from_a_bag(
    tmp_path: Path, release: str, suffix: str, storage: str
) -> None:
    events: list[Event] = [
        *_register(1, 1),
        ArmingCheckRequest(t=1.2, request_id=3, registrations_mask=1),
        ArmingCheckReply(t=1.21, request_id=3, registration_id=0, origin="sent"),
        ExtComponentUnregister(t=1.5, name="Orbit", arming_check_id=0, mode_id=MODE),
    ]
    path = tmp_path / "bag"
    if storage == "mcap":
        path = path.with_suffix(".mcap")
        write_mcap(path, events, release=release)
    else:
        write_rosbag2(path, events, release=release, storage="sqlite3", definitions=False)
    source = open_source(path)
    source.open()
    source.probe()
    read = list(source.events())
    assert [type(e) for e in read] == [type(e) for e in events]
    request, reply, check, answer, gone = read
    assert isinstance(request, ExtComponentRequest) and request.name == "Orbit"
    assert request.where.topic == f"/fmu/in/register_ext_component_request{suffix}"
    assert isinstance(reply, ExtComponentReply) and (reply.success, reply.mode_id) == (True, 23)
    assert isinstance(check, ArmingCheckRequest)
    assert check.registrations_mask == (None if release == "1.16" else 1)
    assert isinstance(answer, ArmingCheckReply) and answer.origin == "sent"
    assert isinstance(gone, ExtComponentUnregister) and gone.name == "Orbit"


def test_each_release_names_its_api_version_in_the_bundled_request() -> None:
    # the .msg files keep MESSAGE_VERSION only; the API version lives in the release record
    assert (
        px4_msgs.message_version(px4_msgs.definition("main", "RegisterExtComponentRequest") or "")
        == 2
    )
    assert px4_msgs.definition("1.14", "RegisterExtComponentRequest") is None
    assert "MSG: px4_msgs/Event" in (px4_msgs.definition("1.17", "ArmingCheckReply") or "")
