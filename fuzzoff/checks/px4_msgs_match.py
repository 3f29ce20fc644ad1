"""OFB006: the companion's px4_msgs do not match the PX4 it talks to (ROS 2 recordings).

From 1.16 PX4 names a ROS 2 topic after its message's version (``/fmu/out/vehicle_status_v1``
on 1.16 and 1.17, ``_v4`` on 1.18: gate.md#drift), and the uXRCE-DDS bridge takes a message
only under its own name and type. A recording says which px4_msgs each side was built with:
the names and embedded definitions of the companion's ``/fmu/in`` topics, and those of PX4's
``/fmu/out`` topics (the reader's ``RecordingInfo.px4_msgs_fits``).

PX4's ROS 2 message translation node (1.16+) republishes a message between its versions: a
recording made with it running holds both names, each with messages. So an ``/fmu/in`` topic of
another release is excused where the same message is also there under a name PX4 takes, and an
``/fmu/out`` name counts as PX4's only where messages came on it (a name with none is a
subscription nobody serves).
"""

from __future__ import annotations

from collections import Counter, defaultdict
from typing import TYPE_CHECKING

from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.events import (
    CommandAck,
    Event,
    FailsafeFlags,
    LandDetected,
    VehicleControlModeStatus,
    VehiclePosition,
    VehicleStatus,
)

if TYPE_CHECKING:
    from fuzzoff.formats.ros2msgs.topics import TopicRef


def parse_topic(topic: str) -> TopicRef | None:
    """``ros2msgs.topics.parse_topic``, imported when a ROS 2 recording first needs it: a lint of
    another format does not load the ROS 2 topic tables (issue 31)."""
    from fuzzoff.formats.ros2msgs.topics import parse_topic as parse

    return parse(topic)


CODE = "OFB006"

PUBLISHED_EVENTS: tuple[type[Event], ...] = (
    VehicleStatus,
    CommandAck,
    FailsafeFlags,
    VehicleControlModeStatus,
    LandDetected,
    VehiclePosition,
)
"""What PX4's ``/fmu/out`` topics become: counted per topic where one message has two names."""


def releases_text(releases: set[str] | tuple[str, ...], order: tuple[str, ...]) -> str:
    names = [r for r in order if r in releases]
    return ", ".join(names) if names else "none"


def _intersection(fits: list[tuple[str, ...]], order: tuple[str, ...]) -> set[str]:
    common = set(order)
    for releases in fits:
        common &= set(releases)
    return common


class Px4MsgsMatch(Check):
    codes = (CODE,)
    wants = ()

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        fits = ctx.info.px4_msgs_fits
        self.order = tuple(dict.fromkeys(r for releases in fits.values() for r in releases))
        self.sent: dict[str, tuple[str, ...]] = {}
        self.published: dict[str, tuple[str, ...]] = {}
        self.sent_names: dict[str, list[str]] = defaultdict(list)
        out_names: dict[str, list[str]] = defaultdict(list)
        for topic, releases in fits.items():
            ref = parse_topic(topic)
            if ref is None or ref.namespace != ctx.vehicle or not releases:
                continue
            if ref.direction == "in":
                self.sent[topic] = releases
                self.sent_names[ref.name].append(topic)
            else:
                self.published[topic] = releases
                out_names[ref.name].append(topic)
        self.doubled = {t for topics in out_names.values() if len(topics) > 1 for t in topics}
        """``/fmu/out`` topics of a message that has two names here."""
        self.counts: Counter[str] = Counter()
        self.subscriptions = PUBLISHED_EVENTS if self.doubled else ()

    def on_event(self, event: Event) -> None:
        self.counts[event.where.topic] += 1

    def finish(self, t_end: float) -> None:
        self._name_and_definition()
        unserved = {t for t in self.doubled if not self.counts[t]}
        px4 = _intersection([r for t, r in self.published.items() if t not in unserved], self.order)
        if not px4:
            return  # PX4's own topics name no release: nothing to compare with
        self._subscribed(unserved, px4)
        self._sent(px4)

    def _sent(self, px4: set[str]) -> None:
        """``/fmu/in`` topics PX4 does not take (unless the same message is also there under a
        name it takes: the translation node's output)."""
        order = self.order
        wrong = {
            topic: releases
            for topic, releases in self.sent.items()
            if not px4 & set(releases) and not self._translated(topic, px4)
        }
        if not wrong:
            return
        companion = _intersection(list(wrong.values()), order)
        built = releases_text(companion, order) if companion else "another release"
        expected = releases_text(px4, order)
        topics = "; ".join(
            f"{topic} fits px4_msgs {releases_text(releases, order)}"
            for topic, releases in wrong.items()
        )
        self.ctx.report(
            CODE,
            f"the companion's messages do not match the PX4 it talks to: {topics} (topic name "
            f"and definition), while PX4's /fmu/out topics fit px4_msgs {expected} only. The "
            f"companion was built with px4_msgs {built}; PX4 expects {expected}. PX4's "
            "uXRCE-DDS bridge takes a message only under its own name and layout, so these "
            "never reach PX4 (no keep-alive, no setpoint, no command) or arrive misread: build "
            "the companion against the px4_msgs branch of PX4's release (or, from 1.16, run "
            "PX4's ROS 2 message translation node beside it)",
            None,
            short=f"companion px4_msgs {built}, PX4 expects {expected}: {len(wrong)} /fmu/in "
            "topic(s) PX4 does not take",
        )

    def _translated(self, topic: str, px4: set[str]) -> bool:
        ref = parse_topic(topic)
        assert ref is not None
        return any(
            px4 & set(self.sent[other]) for other in self.sent_names[ref.name] if other != topic
        )

    def _subscribed(self, unserved: set[str], px4: set[str]) -> None:
        """``/fmu/out`` names of another release with no message on them, beside PX4's name
        for the same message: a companion's subscription that never gets a message."""
        order = self.order
        wrong = sorted(t for t in unserved if not px4 & set(self.published[t]))
        if not wrong:
            return
        said = "; ".join(
            f"{topic} (px4_msgs {releases_text(self.published[topic], order)})" for topic in wrong
        )
        self.ctx.report(
            CODE,
            f"the companion subscribes to {said}, a name of another release than PX4's "
            f"({releases_text(px4, order)}), which publishes the same message under its own "
            "name: no message ever came on it, and a client that waits on it (for OFFBOARD, "
            "say) never sends its setpoints. Build the companion against the px4_msgs branch "
            "of PX4's release, and take the topic names from it",
            None,
            short=f"{', '.join(wrong)}: subscribed under another release's name, never served",
        )

    def _name_and_definition(self) -> None:
        """A topic whose name and embedded definition fit no release together: a program whose
        px4_msgs give one version of the message uses the topic name of another (a name
        written by hand, or kept from an older example)."""
        conflicts = {
            topic: fits
            for topic, fits in self.ctx.info.px4_msgs_conflicts.items()
            if (ref := parse_topic(topic)) is not None and ref.namespace == self.ctx.vehicle
        }
        if not conflicts:
            return
        order = tuple(
            dict.fromkeys(r for pair in conflicts.values() for side in pair for r in side)
        )
        said = "; ".join(
            f"{topic}: its name fits px4_msgs {releases_text(by_name, order)}, its definition "
            f"{releases_text(by_definition, order)}"
            for topic, (by_name, by_definition) in conflicts.items()
        )
        self.ctx.report(
            CODE,
            f"a topic name and its message's px4_msgs disagree: {said}. From 1.16 PX4 names "
            "each topic after its message's version (_vN); a program built with the newer "
            "px4_msgs on the older name (or the reverse) talks on a topic PX4 does not use: "
            "take the topic names from the px4_msgs the program is built with",
            None,
            short=f"{', '.join(conflicts)}: topic name and message version disagree",
        )
