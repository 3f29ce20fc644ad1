"""Which px4_msgs definition decodes which connection, and the decode itself (formats.md 2.3, 3).

Per connection: the definition embedded in the recording first; else a bundled release chosen by
the ``--px4`` release, the topic's ``_vN`` suffix (or the v1.13 naming) and the first payload's
length. Every payload must decode to exactly its length (CDR may pad the end with up to three zero
bytes): a payload that does not is never passed on half-understood; the topic becomes a problem
(OFB001) naming the definition used.
"""

from __future__ import annotations

import math
import struct
from dataclasses import field
from functools import cache
from typing import Any

from rosbags.serde import SerdeError
from rosbags.typesys import get_types_from_idl, get_types_from_msg
from rosbags.typesys.store import Typestore

from fuzzoff.events import NOWHERE, Event, Origin, VehiclePosition, VehicleStatus, Where
from fuzzoff.formats import px4_msgs
from fuzzoff.formats.mavros.convert import MavrosConverter, mavros_topic
from fuzzoff.formats.mavros.ros2 import MavrosTopicDecoder
from fuzzoff.formats.ros2msgs.convert import BUILDERS, KIND_OF, Builder
from fuzzoff.formats.ros2msgs.topics import MESSAGE_FOR_NAME, OUTPUT_MESSAGES, TopicRef, parse_topic
from fuzzoff.formats.typedefs import bounded
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.profiles import PX4_VEHICLE_TYPE
from fuzzoff.recording import Aside, SourceProblem

_DECODE_ERRORS = (struct.error, IndexError, ValueError, TypeError, UnicodeDecodeError, SerdeError)
"""What rosbags' CDR decoders raise on a payload that does not fit its definition (a length
field that points past the end: ``SerdeError``)."""


@dataclass(frozen=True, slots=True)
class Definition:
    """One message definition ready to decode with (a rosbags type store holding it)."""

    typename: str
    source: str
    """``embedded`` or ``bundled <release>``: said in every problem about it."""
    store: Typestore
    fields: frozenset[str]
    layout: tuple[Any, ...]
    little: Any
    big: Any
    cls: Any

    @classmethod
    def make(cls, typename: str, text: str, source: str, fmt: str = "msg") -> Definition:
        if fmt == "idl":
            store = _idl_store(typename, text)
        else:
            store = px4_msgs.typestore_for(typename, text)
        layout = tuple(store.fielddefs[typename][1])
        fields = frozenset(name for name, _ in layout)
        msgdef = store.get_msgdef(typename)
        return cls(
            typename,
            source,
            store,
            fields,
            layout,
            msgdef.deserialize_cdr_le,
            msgdef.deserialize_cdr_be,
            msgdef.cls,
        )

    def decode(self, raw: bytes | memoryview) -> tuple[Any, str | None]:
        """(message, None) when ``raw`` decodes to exactly its length, else (None, why)."""
        if not isinstance(raw, bytes | memoryview):  # a damaged sqlite row holds any type
            return None, f"payload is not bytes but {type(raw).__name__}"
        try:
            if raw[0] or raw[1] > 1:
                return None, "not a CDR payload (bad encapsulation header)"
            func = self.little if raw[1] else self.big
            message, pos = func(raw[4:], 0, self.cls, self.store)
        except SerdeError as exc:
            why = str(exc).rstrip(".")
            return None, f"payload of {len(raw)} bytes does not fit {self.describe()}: {why}"
        except _DECODE_ERRORS:
            size = len(raw)
            return None, f"payload of {size} bytes is shorter than {self.describe()} needs"
        # rosbags' own check tolerates any 3 stray bytes, which hides a newer release's extra
        # trailing field (formats.md 2.3): only zero padding up to a 4-byte boundary is slack.
        extra = len(raw) - 4 - pos
        if extra and not (0 < extra < 4 and len(raw) % 4 == 0 and not any(raw[-extra:])):
            return None, f"payload of {len(raw)} bytes, {4 + pos} decoded by {self.describe()}"
        return message, None

    def describe(self) -> str:
        return f"{self.typename} ({self.source} definition)"


def _idl_store(typename: str, text: str) -> Typestore:
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.EMPTY)
    store.register(bounded(get_types_from_idl(text)))
    return store


@cache
def bundled(message: str, release: str) -> Definition | None:
    """A bundled definition, compiled once per process."""
    text = px4_msgs.definition(release, message)
    if text is None:
        return None
    return Definition.make(px4_msgs.type_name(message), text, f"bundled {release}")


@cache
def bundled_layout(message: str, release: str) -> tuple[Any, ...] | None:
    """The field layout of a bundled definition, parsed only: a type store would also generate
    and compile its deserialisers (three times the cost), and only the layout is compared.
    rosbags' store keeps the parser's field list as is, so the two layouts compare equal."""
    text = px4_msgs.definition(release, message)
    if text is None:
        return None
    return _parsed_layout(px4_msgs.type_name(message), text)


@cache
def _parsed_layout(typename: str, text: str) -> tuple[Any, ...]:
    """One parse per distinct text (releases often share a message's text)."""
    return tuple(get_types_from_msg(text, typename)[typename][1])


def message_of(topic: str, msgtype: str) -> tuple[str | None, TopicRef | None]:
    """The px4_msgs message a connection carries (by type, else by PX4 topic name)."""
    ref = parse_topic(topic)
    pkg, _, name = msgtype.replace("/msg/", "/").partition("/")
    if pkg == px4_msgs.PACKAGE and name in BUILDERS:
        return name, ref
    if ref is not None and ref.name in MESSAGE_FOR_NAME and not msgtype:
        return MESSAGE_FOR_NAME[ref.name], ref
    return None, ref


def px4_topic(topic: str, msgtype: str) -> bool:
    """A topic fuzzoff reads, or must say it could not: a PX4 message type, or the name of a
    PX4 topic it decodes whatever type it is recorded as."""
    message, ref = message_of(topic, msgtype)
    return message is not None or (ref is not None and ref.name in MESSAGE_FOR_NAME)


@dataclass(slots=True)
class TopicDecoder:
    """Decodes one connection's payloads into events; counts what it could not decode."""

    topic: str
    message: str
    vehicle: str
    origin: Origin
    ref: TopicRef | None
    owner: Ros2Decoding
    definition: Definition | None = None
    builder: Builder | None = None
    index: int = 0
    failed: int = 0
    first_failure: tuple[float, str] | None = None
    unusable: str | None = None
    """Why no definition can decode this topic (then every message is counted as failed)."""

    def event(self, raw: bytes | memoryview, t: float) -> Event | None:
        """The event for one payload, or None (not decodable: counted as a problem).

        The usual payload (a definition in use, little-endian CDR, decoding to its exact
        length) is decoded here in one step; anything else goes through ``decode``, whose
        verdict is the same function of the same bytes, so the events are the same.
        """
        index = self.index
        self.index = index + 1
        build = self.builder
        definition = self.definition
        if build is not None and definition is not None:
            message: Any = None
            try:
                if raw[1] == 1 and not raw[0]:
                    message, pos = definition.little(raw[4:], 0, definition.cls, definition.store)
            except _DECODE_ERRORS:
                message = None
            if message is not None and pos == len(raw) - 4:
                try:
                    return build(message, t, Where(self.topic, index), message.timestamp)
                except AttributeError as exc:
                    self.drop_definition(exc)
        return self._checked(raw, t, index)

    def _checked(self, raw: bytes | memoryview, t: float, index: int) -> Event | None:
        """``event`` for any payload: definition chosen if need be, every failure counted."""
        if self.builder is None:
            if self.unusable is None:
                self.resolve(raw, t)
            if self.builder is None:
                self._fail(t, self.unusable or "")
                return None
        assert self.definition is not None
        message, why = self.definition.decode(raw)
        if why is not None:
            self._fail(t, why)
            return None
        try:
            return self.builder(message, t, Where(self.topic, index), message.timestamp)
        except AttributeError as exc:
            self.drop_definition(exc)
            return self._checked(raw, t, index)

    def resolve(self, sample: bytes | memoryview, t: float) -> None:
        """Choose a bundled definition from a sample payload; else say why not (``unusable``)."""
        definition, why = self.owner.choose(self, sample)
        if definition is None:
            self.unusable = why
            return
        self.use(definition)

    @property
    def kind(self) -> str:
        return KIND_OF[self.message]

    def use(self, definition: Definition) -> None:
        self.definition = definition
        self.builder = BUILDERS[self.message](definition.fields, self.vehicle, self.origin)

    def drop_definition(self, missing: AttributeError) -> None:
        """The definition decodes the payload but lacks a field the event is made from (an
        embedded definition renamed or damaged). As for embedded text rosbags cannot parse, the
        bundled definitions take over (still checked against every payload) and a note says
        so; a bundled one never lacks a field, but would make the topic unusable."""
        definition = self.definition
        assert definition is not None
        self.definition = self.builder = None
        lacks = f"{definition.describe()} has no field {missing.name!r}"
        if definition.source == "embedded":
            self.owner.notes.append(f"{self.topic}: {lacks}; bundled px4_msgs used")
        else:
            self.unusable = lacks

    def _fail(self, t: float, why: str) -> None:
        self.failed += 1
        if self.first_failure is None:
            self.first_failure = (t, why)


@dataclass(slots=True)
class ThinnedTopicDecoder(TopicDecoder):
    """A topic read at most once per ``period_s`` of log time (the vehicle's position in a
    plain lint, ``POSITION_PERIOD_S``): the first message of each period is decoded, the
    others are counted and skipped undecoded."""

    period_s: float = 0.0
    due: float = -math.inf

    def event(self, raw: bytes | memoryview, t: float) -> Event | None:
        if t < self.due:
            self.index += 1
            aside = self.owner.aside
            aside.read(t)
            if aside.plot is not None:
                event = self._plotted(raw, t)
                if isinstance(event, VehiclePosition):
                    aside.plot.position(event)
            return None
        self.due = (t // self.period_s + 1) * self.period_s
        return TopicDecoder.event(self, raw, t)

    def _plotted(self, raw: bytes | memoryview, t: float) -> Event | None:
        """The event of a thinned message, for the plots only: nothing is counted or chosen
        (a message that needs either is left out of the plot)."""
        build, definition = self.builder, self.definition
        if build is None or definition is None:
            return None
        message, why = definition.decode(raw)
        if why is not None:
            return None
        try:
            return build(message, t, Where(self.topic, self.index - 1), message.timestamp)
        except AttributeError:
            return None


@dataclass(slots=True)
class Ros2Decoding:
    """The per-recording choice of definitions, and the problems it found.

    ``release`` is the ``--px4`` release (bundled folder name) when the user gave one.
    """

    release: str | None = None
    decoders: list[Decoder] = field(default_factory=list)
    mavros: MavrosConverter = field(default_factory=MavrosConverter)
    unknown: list[tuple[str, str]] = field(default_factory=list)
    """PX4 topics recorded as a type fuzzoff cannot decode (name, type)."""
    unread: dict[tuple[str, str], int] = field(default_factory=dict)
    """How many messages of each of ``unknown`` the recording holds, where the reader counted."""
    evidence: set[str] | None = None
    """Releases every definition seen so far fits (for profile detection)."""
    by_text: set[str] | None = None
    """Releases whose ``.msg`` text declares ``MESSAGE_VERSION`` as the recording's embedded
    definitions do (or lack it as they do): where layouts are equal, the text tells 1.15 from
    1.16+."""
    topic_fits: dict[str, set[str]] = field(default_factory=dict)
    """Per PX4 topic, the releases its name and its embedded definition fit (a definition
    fuzzoff chose for a bag without one is no evidence of what the sender was built with)."""
    name_fits: dict[str, set[str]] = field(default_factory=dict)
    """Per PX4 topic, the releases its name alone fits."""
    definition_fits: dict[str, set[str]] = field(default_factory=dict)
    """Per PX4 topic, the releases its embedded definition alone fits."""
    notes: list[str] = field(default_factory=list)
    position_period_s: float = 0.0
    """``VehicleLocalPosition`` read at most this often per topic (0: every message)."""
    aside: Aside = field(default_factory=Aside)
    """Where thinned positions go (their time; the plots, when asked)."""

    def thin_positions(self, period_s: float, aside: Aside) -> None:
        """Read the vehicle's position at most once per ``period_s`` (MAVROS's too); the
        others go to ``aside``."""
        self.position_period_s = period_s
        self.mavros.position_period_s = period_s
        self.aside = self.mavros.aside = aside

    def connection(
        self, topic: str, msgtype: str, embedded: str | None, fmt: str = "msg"
    ) -> Decoder | None:
        """A decoder for a connection, or None when it is not a topic fuzzoff decodes."""
        split = mavros_topic(topic, msgtype)
        if split is not None:
            handler = self.mavros.handler(topic)
            if handler is None:
                return None
            embedded_msg = embedded if fmt == "msg" else None
            mavros = MavrosTopicDecoder.make(topic, msgtype, split, handler, embedded_msg)
            self.decoders.append(mavros)
            return mavros
        message, ref = message_of(topic, msgtype)
        if message is None:
            if ref is not None and ref.name in MESSAGE_FOR_NAME:
                self.unknown.append((topic, msgtype))
            return None
        if ref is not None:
            vehicle = ref.namespace
            origin: Origin = "vehicle" if ref.direction == "out" else "sent"
        else:
            head, sep, _ = topic.partition("/fmu/")
            vehicle = head if sep else ""
            origin = "vehicle" if message in OUTPUT_MESSAGES else "sent"
        if message == "VehicleLocalPosition" and self.position_period_s:
            decoder: TopicDecoder = ThinnedTopicDecoder(
                topic, message, vehicle, origin, ref, self, period_s=self.position_period_s
            )
        else:
            decoder = TopicDecoder(topic, message, vehicle, origin, ref, self)
        self.decoders.append(decoder)
        self._note_naming(decoder)
        if embedded and embedded.strip():
            try:
                definition = Definition.make(px4_msgs.type_name(message), embedded, "embedded", fmt)
            except Exception as exc:  # rosbags raises many types on bad text
                # Fall back to the bundled definitions (still checked against every payload).
                why = " ".join(str(exc).split())[:80]
                self.notes.append(
                    f"{topic}: embedded definition not usable ({why}); bundled px4_msgs used"
                )
                return decoder
            self._note_evidence(
                message, definition, decoder.topic, embedded if fmt == "msg" else None
            )
            decoder.use(definition)
        return decoder

    def _note_naming(self, decoder: TopicDecoder) -> None:
        """A PX4 topic name tells releases too: its ``_vN`` suffix is the message's
        ``MESSAGE_VERSION`` in the releases that publish it so (none = 0), and the v1.13
        naming is 1.13's. A name that fits none (a bridge renamed it) tells nothing."""
        if decoder.ref is None:
            return
        fits = set(self.candidates(decoder))
        if fits:
            self.evidence = fits if self.evidence is None else self.evidence & fits
            self._topic_fits(decoder.topic, fits)
            self.name_fits[decoder.topic] = fits

    def _note_evidence(
        self, message: str, definition: Definition, topic: str = "", text: str | None = None
    ) -> None:
        """Narrow the releases to those whose bundled ``message`` has this layout. A ``.msg``
        text (``text``, the recording's own) also tells where layouts are equal: 1.16 added
        ``MESSAGE_VERSION`` to the messages it versions (``by_text``, a preference only)."""
        fits = {
            r
            for r in px4_msgs.releases_with(message)
            if bundled_layout(message, r) == definition.layout
        }
        if text is not None:
            declared = _declared_version(text)
            same = {r for r in fits if _declared_version(_bundled_text(r, message)) == declared}
            self.by_text = same if self.by_text is None else self.by_text & same
        self.evidence = fits if self.evidence is None else self.evidence & fits
        if topic:
            self._topic_fits(topic, fits)
            self.definition_fits[topic] = fits

    def _topic_fits(self, topic: str, fits: set[str]) -> None:
        known = self.topic_fits.get(topic)
        self.topic_fits[topic] = set(fits) if known is None else known & fits

    def px4_msgs_conflicts(self) -> dict[str, tuple[tuple[str, ...], tuple[str, ...]]]:
        """PX4 topics whose name and embedded definition fit no release together -> (the
        releases the name fits, those the definition fits), oldest first: a program whose
        px4_msgs give one version of the message, on the topic name of another."""
        order = px4_msgs.folders()
        out: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {}
        for topic, fits in sorted(self.topic_fits.items()):
            by_name = self.name_fits.get(topic)
            if fits or not by_name or topic not in self.definition_fits:
                continue
            by_definition = self.definition_fits[topic]
            out[topic] = (
                tuple(r for r in order if r in by_name),
                tuple(r for r in order if r in by_definition),
            )
        return out

    def px4_msgs_fits(self) -> dict[str, tuple[str, ...]]:
        """Per PX4 topic, the bundled releases (oldest first) its name and embedded definition
        fit: what the program on each side was built with (``RecordingInfo.px4_msgs_fits``)."""
        order = px4_msgs.folders()
        return {
            topic: tuple(r for r in order if r in fits)
            for topic, fits in sorted(self.topic_fits.items())
        }

    def candidates(self, decoder: TopicDecoder) -> list[str]:
        """Bundled releases that can carry this topic (suffix / naming), newest first."""
        out = []
        ref = decoder.ref
        for release in reversed(px4_msgs.releases_with(decoder.message)):
            text = px4_msgs.definition(release, decoder.message)
            assert text is not None
            version = px4_msgs.message_version(text)
            if ref is not None and ref.legacy and release != "1.13":
                continue
            if ref is not None and not ref.legacy and (ref.version or 0) != version:
                continue
            out.append(release)
        return out

    def choose(
        self, decoder: TopicDecoder, sample: bytes | memoryview
    ) -> tuple[Definition | None, str]:
        """A bundled definition for a connection without one (formats.md 2.3 rule 2)."""
        candidates = self.candidates(decoder)
        if self.release is not None and self.release in candidates:
            chosen = bundled(decoder.message, self.release)
            assert chosen is not None
            _, why = chosen.decode(sample)
            if why is not None:
                return None, f"no embedded definition and {why} (--px4 {self.release})"
            return chosen, ""
        fitting: list[Definition] = []
        for release in candidates:
            definition = bundled(decoder.message, release)
            if definition is not None and definition.decode(sample)[1] is None:
                fitting.append(definition)
        if not fitting:
            tried = ", ".join(candidates) or "none for this topic name"
            return None, (
                f"no embedded definition, and the {len(sample)}-byte payload fits no bundled "
                f"px4_msgs release (tried {tried}); give --px4 or record with definitions"
            )
        if self.evidence:
            preferred = [d for d in fitting if d.source.split()[-1] in self.evidence]
            fitting = preferred or fitting
        chosen = fitting[0]
        release = chosen.source.split()[-1]
        others = {d.source.split()[-1] for d in fitting if d.layout != chosen.layout}
        if others:
            self.notes.append(
                f"{decoder.topic}: no embedded definition; decoded as px4_msgs {release} "
                f"(the payload also fits {', '.join(sorted(others))}; --px4 decides)"
            )
        self._note_evidence(decoder.message, chosen)
        return chosen, ""

    def _fits(self) -> set[str] | None:
        """The releases every layout and topic name fits, narrowed by the definitions' text
        where that leaves any (a recording whose programs mix px4_msgs keeps its layouts')."""
        if self.evidence and self.by_text and self.evidence & self.by_text:
            return self.evidence & self.by_text
        return self.evidence

    def detected_release(self) -> str | None:
        """The one release every embedded or chosen definition and every PX4 topic name fits,
        if exactly one (named as ``px4_msgs.first_release_of`` names its folder)."""
        fits = self._fits()
        if fits and len(fits) == 1:
            return px4_msgs.first_release_of(next(iter(fits)))
        return None

    def fitting_releases(self) -> list[str]:
        """The releases (oldest first) the definitions and topic names fit, where they narrow
        it to several: the release is then not known, but it is one of these."""
        fits = self._fits()
        if not fits or len(fits) == 1:
            return []
        return [px4_msgs.first_release_of(r) for r in px4_msgs.folders() if r in fits]

    def vehicle_from(self, decoder: Decoder | None, raw: bytes | memoryview) -> str | None:
        """The vehicle type one ``VehicleStatus`` payload names (None for anything else)."""
        if not isinstance(decoder, TopicDecoder) or decoder.message != "VehicleStatus":
            return None
        if decoder.definition is None and decoder.unusable is None:
            decoder.resolve(raw, 0.0)
        if decoder.definition is None or decoder.builder is None:
            return None
        decoded, why = decoder.definition.decode(raw)
        if why is not None:
            return None
        try:
            status = decoder.builder(decoded, 0.0, NOWHERE, 0)
        except AttributeError as exc:
            decoder.drop_definition(exc)
            return self.vehicle_from(decoder, raw)
        return self.vehicle_type(status)

    def vehicle_type(self, status: Event) -> str | None:
        """The profile vehicle type a decoded ``VehicleStatus`` names (VTOL first)."""
        if not isinstance(status, VehicleStatus):
            return None
        if status.is_vtol:
            return "vtol"
        return PX4_VEHICLE_TYPE.get(status.vehicle_type or 0)

    def kinds(self) -> set[str]:
        return {d.kind for d in self.decoders}

    def rover_topics(self) -> list[str]:
        """Topics of PX4's rover setpoints (``Rover*Setpoint``, 1.16+): a rover's recording."""
        return sorted(
            d.topic
            for d in self.decoders
            if isinstance(d, TopicDecoder) and d.message.startswith("Rover")
        )

    def vehicles(self) -> list[str]:
        return sorted({d.vehicle for d in self.decoders})

    def count_unread(self, topic: str, msgtype: str, messages: int) -> None:
        """``messages`` more messages of an ``unknown`` topic were not read."""
        key = (topic, msgtype)
        self.unread[key] = self.unread.get(key, 0) + messages

    def problems(self) -> list[SourceProblem]:
        out = []
        for topic, msgtype in self.unknown:
            held = self.unread.get((topic, msgtype))
            unread = f"its {held} messages were not read" if held is not None else "not read"
            if held == 1:
                unread = "its 1 message was not read"
            out.append(
                SourceProblem(
                    f"topic {topic} has message type {msgtype or '(none)'}, which fuzzoff "
                    f"cannot decode as a PX4 topic: {unread}",
                    topic,
                )
            )
        for d in self.decoders:
            if d.first_failure is None:
                continue
            t, why = d.first_failure
            count = f"{d.failed} of {d.index} messages" if d.index else "messages"
            out.append(SourceProblem(f"{d.message}: {why}; {count} not decoded", d.topic, t))
        return out


Decoder = TopicDecoder | MavrosTopicDecoder
"""What readers hold per connection: ``event(raw, t)``, plus counts for the problems."""


def _bundled_text(release: str, message: str) -> str:
    text = px4_msgs.definition(release, message)
    assert text is not None
    return text


def _declared_version(text: str) -> int | None:
    """The ``MESSAGE_VERSION`` a ``.msg`` text declares at its top level (None: it declares
    none; the nested definitions a recorder appends after ``===`` lines are not its own)."""
    own = text.split("\n===", 1)[0]
    return px4_msgs.message_version(own) if px4_msgs.declares_version(own) else None
