"""A ``Delivery`` as OFB108 findings and as the terminal's lines.

One finding per stretch in which PX4 received none of what the companion kept sending (the
``/fmu/in`` topics' undelivered windows that overlap, merged; the bridge's discovery at the
start is left to the JSON), one per command PX4 never received, and one per status change of
PX4 (mode, failsafe, the offboard signal lost) that the companion received ``LATE_S`` or more
late, or never, outside those stretches. ``error`` while armed (PX4's ULog) or when PX4 flagged
the offboard signal lost in the stretch; ``warning`` otherwise.
"""

from __future__ import annotations

from fuzzoff.bridge.changes import LATE_S, Change
from fuzzoff.bridge.compare import Delivery, TopicResult, Window
from fuzzoff.events import Where
from fuzzoff.findings import Finding, Severity

CODE, NAME = "OFB108", "sent-not-received"
MIN_WINDOW_S = 0.5
"""A stream's undelivered stretch this long is a finding (PX4's keep-alive needs > 2 Hz)."""
COMMANDS = {
    20: "NAV_RETURN_TO_LAUNCH",
    21: "NAV_LAND",
    22: "NAV_TAKEOFF",
    176: "DO_SET_MODE",
    400: "COMPONENT_ARM_DISARM",
}


def _late(change: Change) -> str:
    if change.seen_after_s is None:
        return "the companion never received it"
    return f"the companion received it {change.seen_after_s:.1f} s later"


def _did(change: Change) -> str:
    return "flagged the offboard signal lost" if change.lost_signal else f"went to {change.what}"


def _stretches(delivery: Delivery) -> list[tuple[float, float, list[tuple[TopicResult, Window]]]]:
    """The streams' undelivered windows, overlapping ones merged, in time order."""
    windows = sorted(
        (
            (w, t)
            for t in delivery.topics
            if t.direction == "in" and t.name != "vehicle_command"
            for w in t.windows
            if not w.discovery and w.end_s - w.start_s >= MIN_WINDOW_S
        ),
        key=lambda wt: wt[0].start_s,
    )
    out: list[tuple[float, float, list[tuple[TopicResult, Window]]]] = []
    for window, topic in windows:
        if out and window.start_s <= out[-1][1]:
            start, end, members = out[-1]
            out[-1] = (start, max(end, window.end_s), [*members, (topic, window)])
        else:
            out.append((window.start_s, window.end_s, [(topic, window)]))
    return out


def _armed_at(delivery: Delivery, time_s: float) -> bool:
    status = [c for c in delivery.changes if not c.what.startswith("offboard signal")]
    before = [c for c in status if c.time_s <= time_s]
    return bool(before and before[-1].armed and "disarmed" not in before[-1].what)


def findings(delivery: Delivery) -> list[Finding]:
    out: list[Finding] = []
    told: set[int] = set()
    silent = [(t, w) for t in delivery.topics if t.direction == "out" for w in t.windows]
    for start, end, members in _stretches(delivery):
        sent = " and ".join(f"{w.count} {t.topic}" for t, w in members)
        inside = [(i, c) for i, c in enumerate(delivery.changes) if start - 0.05 <= c.time_s <= end]
        lost = any(c.lost_signal for _, c in inside)
        what = "; ".join(
            f"at {c.time_s:.2f} s PX4 {_did(c)} ({_late(c)})"
            for _, c in inside
            if c.lost_signal or not c.what.startswith("offboard signal")
        )
        told.update(i for i, _ in inside)
        quiet = [w for _, w in silent if w.start_s < end and w.end_s > start]
        link = ""
        if quiet:
            first, last = min(w.start_s for w in quiet), max(w.end_s for w in quiet)
            link = (
                f"; nothing from PX4 reached the companion either from {first:.2f} to"
                f" {last:.2f} s: the bridge itself was down (the agent or its link)"
            )
        message = (
            f"PX4 received none of the {sent} messages the companion sent from {start:.2f} to"
            f" {end:.2f} s ({end - start:.1f} s, by PX4's ULog {delivery.ulog})"
            + (f"; {what}" if what else "")
            + link
            + ". The companion kept publishing as if PX4 were following"
        )
        severity = Severity.ERROR if lost or _armed_at(delivery, start) else Severity.WARNING
        summary = f"PX4 received nothing the companion sent for {end - start:.1f} s"
        if lost:
            summary += " and flagged the offboard signal lost"
        out.append(
            Finding(
                CODE, NAME, severity, message, start, Where(members[0][0].topic), "", end, summary
            )
        )
    for topic in delivery.topics:
        if topic.name != "vehicle_command":
            continue
        for window in topic.windows:
            message = (
                f"PX4 never received the VehicleCommand sent at {window.start_s:.2f} s: it is"
                f" not in PX4's ULog {delivery.ulog}, which holds every command PX4 received"
            )
            out.append(
                Finding(
                    CODE,
                    NAME,
                    Severity.ERROR,
                    message,
                    window.start_s,
                    Where(topic.topic),
                    summary="a command PX4 never received",
                )
            )
    for i, change in enumerate(delivery.changes):
        late = change.seen_after_s is None or change.seen_after_s >= LATE_S
        if i in told or not late:
            continue
        what = (
            "flagged the offboard signal lost" if change.lost_signal else f"went to {change.what}"
        )
        message = f"PX4 {what} at {change.time_s:.2f} s; {_late(change)}"
        severity = Severity.ERROR if change.armed else Severity.WARNING
        out.append(
            Finding(
                CODE,
                NAME,
                severity,
                message,
                change.time_s,
                Where("vehicle_status"),
                summary=f"PX4 {what}; {_late(change)}",
            )
        )
    return out


def lines(delivery: Delivery) -> list[str]:
    """The terminal's table: one line per topic, then PX4's status changes."""
    clock = delivery.clock
    source = (
        f"{clock.pairs} of PX4's outputs, within {clock.residual_us / 1000:.1f} ms"
        if clock.pairs
        else "the bridge's time sync offset alone (the bag holds no PX4 output)"
    )
    out = [
        f"sent against received, with {delivery.ulog} (PX4's clock runs at {clock.rate:.3f} of"
        f" the host's, measured by {source})"
    ]
    for topic in delivery.topics:
        arrow = "->" if topic.direction == "in" else "<-"
        if topic.note and not topic.logged:
            out.append(f"  {arrow} {topic.topic}: {topic.recorded} recorded, {topic.note}")
            continue
        if topic.direction == "in":
            text = f"{topic.recorded} sent, {topic.logged} in PX4's log"
            text += f", {topic.undelivered} not received" if topic.undelivered else ", all received"
        else:
            text = f"{topic.recorded} received, PX4 published {topic.logged}"
            if topic.windows:
                text += ", none reached the companion " + ", ".join(
                    f"{w.start_s:.2f}-{w.end_s:.2f} s" for w in topic.windows
                )
        for window in topic.windows:
            if window.discovery:
                text += f" ({window.count} before PX4 matched the writer)"
            elif topic.direction == "in":
                text += f" [{window.start_s:.2f}-{window.end_s:.2f} s: {window.count}]"
        if topic.latency_ms is not None:
            median, worst, _ = topic.latency_ms
            text += f"; latency {median:.1f} ms median, {worst:.1f} ms max"
        if topic.note:
            text += f"; {topic.note}"
        out.append(f"  {arrow} {topic.topic}: {text}")
    for change in delivery.changes:
        seen = (
            "never seen by the companion"
            if change.seen_after_s is None
            else f"seen {change.seen_after_s:.2f} s later"
        )
        out.append(f"  PX4 {change.time_s:7.2f} s  {change.what}: {seen}")
    if delivery.changes_note:
        out.append(f"  PX4's status: {delivery.changes_note}")
    return out
