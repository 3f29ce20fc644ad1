"""OFB006: the companion's px4_msgs do not match the PX4 it talks to (ROS 2 recordings).

From 1.16 PX4 names a ROS 2 topic after its message's version (``/fmu/out/vehicle_status_v1``
on 1.16 and 1.17, ``_v4`` on 1.18: gate spec §16 S9), and the uXRCE-DDS bridge takes a message
only under its own name and type. A recording says which px4_msgs each side was built with:
the names and embedded definitions of the companion's ``/fmu/in`` topics, and those of PX4's
``/fmu/out`` topics (the reader's ``RecordingInfo.px4_msgs_fits``). A companion topic that fits
none of the releases PX4's topics fit is one PX4 does not take.
"""

from __future__ import annotations

from collections import defaultdict

from fuzzoff.checks.base import Check, CheckContext
from fuzzoff.formats.ros2msgs.topics import parse_topic

CODE = "OFB006"


def releases_text(releases: set[str] | tuple[str, ...], order: tuple[str, ...]) -> str:
    names = [r for r in order if r in releases]
    return ", ".join(names) if names else "none"


class Px4MsgsMatch(Check):
    codes = (CODE,)
    wants = ()

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.subscriptions = ()

    def finish(self, t_end: float) -> None:
        self._name_and_definition()
        fits = self.ctx.info.px4_msgs_fits
        if not fits:
            return
        order = tuple(dict.fromkeys(r for releases in fits.values() for r in releases))
        sent: dict[str, tuple[str, ...]] = {}
        published: dict[str, tuple[str, ...]] = {}
        names: dict[str, list[str]] = defaultdict(list)
        for topic, releases in fits.items():
            ref = parse_topic(topic)
            if ref is None or ref.namespace != self.ctx.vehicle or not releases:
                continue
            (sent if ref.direction == "in" else published)[topic] = releases
            if ref.direction == "out":
                names[ref.name].append(topic)
        if not published:
            return
        px4: set[str] = set(order)
        for releases in published.values():
            px4 &= set(releases)
        if not px4:
            self._two_versions(names, published, order)
            return
        wrong = {topic: releases for topic, releases in sent.items() if not px4 & set(releases)}
        if not wrong:
            return
        companion: set[str] = set(order)
        for releases in wrong.values():
            companion &= set(releases)
        built = releases_text(companion, order) if companion else "another release"
        topics = "; ".join(
            f"{topic} fits px4_msgs {releases_text(releases, order)}"
            for topic, releases in wrong.items()
        )
        self.ctx.report(
            CODE,
            f"the companion's messages do not match the PX4 it talks to: {topics} (topic name "
            f"and definition), while PX4's /fmu/out topics fit px4_msgs "
            f"{releases_text(px4, order)} only. The companion was built with px4_msgs "
            f"{built}; PX4 expects {releases_text(px4, order)}. PX4's uXRCE-DDS bridge takes a "
            "message only under its own name and layout, so these never reach PX4 (no "
            "keep-alive, no setpoint, no command) or arrive misread: build the companion "
            "against the px4_msgs branch of PX4's release",
            None,
            short=f"companion px4_msgs {built}, PX4 expects {releases_text(px4, order)}: "
            f"{len(wrong)} /fmu/in topic(s) PX4 does not take",
        )

    def _two_versions(
        self,
        names: dict[str, list[str]],
        published: dict[str, tuple[str, ...]],
        order: tuple[str, ...],
    ) -> None:
        """PX4's topics fit no release together: one message under two version names (a
        companion subscribed to the name its px4_msgs give, PX4 publishes the other)."""
        doubled = {name: topics for name, topics in names.items() if len(topics) > 1}
        if not doubled:
            return
        said = "; ".join(
            " and ".join(f"{t} (px4_msgs {releases_text(published[t], order)})" for t in topics)
            for topics in doubled.values()
        )
        self.ctx.report(
            CODE,
            f"one PX4 message under two version names: {said}. PX4 publishes only the name of "
            "its own release; the other is a subscription of a companion built with another "
            "px4_msgs, which never gets a message (a client waiting for OFFBOARD on it never "
            "sends its setpoints): build the companion against the px4_msgs branch of PX4's "
            "release",
            None,
            short=f"{' / '.join(t for topics in doubled.values() for t in topics)}: two "
            "versions of one message, one of them from the wrong px4_msgs",
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
