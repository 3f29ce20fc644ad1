"""OFB606 (SET_ATTITUDE_TARGET type_mask) and OFB607 (setpoints addressed to another vehicle).

OFB606 follows seed 000 "MAVLink Offboard Control" / seed 002 "MAVLink 消息": attitude or body
rates, each with thrust. OFB607 follows PX4's receiver (gate.md#receiver): a setpoint whose
``target_system`` is neither the vehicle's system id nor 0, or whose ``target_component`` is
neither its component id nor 0, is dropped, keep-alive included. The vehicle's ids are what the
recording shows: the system id its own messages come from (HEARTBEAT and the rest), or the
``MAV_SYS_ID`` / ``MAV_COMP_ID`` parameters; the component is PX4's autopilot (1) otherwise.
"""

from __future__ import annotations

from operator import attrgetter

from fuzzoff.checks._episodes import Episodes, Offence
from fuzzoff.checks._runs import commit_alike, first_of_each, sent_only
from fuzzoff.checks.base import Check, CheckContext, StreamBatch
from fuzzoff.events import Event, MavlinkTarget, SetAttitudeTarget, Where
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.tables import mavlink as tm

AUTOPILOT_COMPONENT = 1

_ORIGIN = attrgetter("origin")
_MASK = attrgetter("type_mask")
_ROUTE = attrgetter("origin", "transport")
_JUDGED = ("sent", "mavlink")
"""The route of the MAVLink setpoints ``on_event`` judges: recorded as MAVLink on its way to
the vehicle."""
_TARGET = attrgetter("target_system", "target_component")
"""What the verdict on such a setpoint depends on."""


class AttitudeTargetMask(Check):
    codes = ("OFB606",)
    wants = (SetAttitudeTarget,)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx)
        self.stream_types = self.wants
        self.by_mask: dict[int, dict[str, Offence]] = {}

    def on_event(self, event: Event) -> None:
        if event.origin != "sent" or not isinstance(event, SetAttitudeTarget):
            return
        rules = tm.attitude_rules(self.ctx.profile)
        if rules is None or not rules.supported:
            return  # no page for this profile, or a rover (OFB507)
        offences = self._offences(event.type_mask)
        self.episodes.update("OFB606", event.kind, event.t, event.where, offences)

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path: the offences depend only on the type_mask (``commit_alike``)."""
        events = sent_only(batch.of(self.stream_types))
        if not events:
            return
        rules = tm.attitude_rules(self.ctx.profile)
        if rules is None or not rules.supported:
            return
        verdicts = [[("OFB606", self._offences(mask))] for mask in set(map(_MASK, events))]
        if not commit_alike(self.episodes, events[0].kind, events, verdicts):
            self.replay(batch)

    def _offences(self, mask: int) -> dict[str, Offence]:
        """What a SET_ATTITUDE_TARGET with this type_mask offends (the same for every one)."""
        known = self.by_mask.get(mask)
        if known is None:
            known = self.by_mask[mask] = self._judge(mask)
        return known

    def _judge(self, mask: int) -> dict[str, Offence]:
        offences: dict[str, Offence] = {}
        head = f"SET_ATTITUDE_TARGET type_mask {mask}"
        if not tm.attitude_used(mask) and not tm.rates_used(mask):
            offences["neither"] = Offence(
                f"{head} ignores both the attitude and the body rates (roll and pitch rate): "
                "PX4 publishes nothing for it (no setpoint, no keep-alive)"
            )
        if not tm.thrust_used(mask):
            if self.ctx.profile.release.attitude_target_needs_thrust:
                effect = (
                    f"PX4 {self.ctx.profile.px4} ignores such a message entirely (no setpoint, "
                    "no keep-alive)"
                )
            else:
                effect = (
                    f"PX4 {self.ctx.profile.px4} accepts it and flies a thrust of 0 with an "
                    "attitude setpoint"
                )
            offences["thrust"] = Offence(
                f"{head} ignores the thrust: the docs support attitude or body rates only "
                f"together with thrust; {effect}"
            )
        return offences

    def finish(self, t_end: float) -> None:
        self.episodes.finish()


@dataclass(slots=True)
class _Pending:
    """Setpoints to one target seen before the vehicle's own id was known."""

    t: float
    where: Where
    last_t: float
    count: int = 1


class SetpointTarget(Check):
    codes = ("OFB607",)
    wants = (Event,)

    def __init__(self, ctx: CheckContext) -> None:
        super().__init__(ctx)
        self.episodes = Episodes(ctx)
        self.autopilot_seen = False
        self.pending: dict[tuple[int, int], _Pending] = {}
        self.judged: dict[tuple[int, int, tuple[int, int] | None], dict[str, Offence]] = {}
        """Verdicts by (target system, target component, the vehicle's ids)."""
        self.setpoint_types = (MavlinkTarget,)

    def _own_ids(self) -> tuple[int, int] | None:
        params = self.ctx.state.params
        sysid: int | None = None
        if "MAV_SYS_ID" in params:
            sysid = int(params["MAV_SYS_ID"])
        elif self.autopilot_seen and self.ctx.vehicle.isdigit():
            sysid = int(self.ctx.vehicle)
        if sysid is None:
            return None
        return sysid, int(params.get("MAV_COMP_ID", AUTOPILOT_COMPONENT))

    def on_event(self, event: Event) -> None:
        if event.origin == "vehicle":
            self.autopilot_seen = self.autopilot_seen or event.vehicle.isdigit()
            if self.pending and self._own_ids() is not None:
                self._resolve_pending()
            return
        if event.origin != "sent" or not isinstance(event, MavlinkTarget):
            return
        if event.transport != "mavlink":
            return  # MAVROS fills the ids from its own parameters: not in the recording
        if self._own_ids() is None:
            self._add_one(event)
            return
        self.episodes.update("OFB607", "setpoints", event.t, event.where, self._judge(event))

    def on_batch(self, batch: StreamBatch) -> None:
        """Fast path. The vehicle's own messages of the run change nothing unless they are the
        first sign of its autopilot or could resolve pending setpoints (then replay). Before the
        vehicle's ids are known the setpoints only join ``pending``; after, their verdict
        depends only on the target ids (``commit_alike``)."""
        may_change = (not self.autopilot_seen and self.ctx.vehicle.isdigit()) or (
            self.pending and self._own_ids() is not None
        )
        if may_change and "vehicle" in set(map(_ORIGIN, batch.events)):
            self.replay(batch)
            return
        setpoints = batch.of(self.setpoint_types)  # judged: sent as MAVLink
        judged = [route == _JUDGED for route in set(map(_ROUTE, setpoints))]
        if not any(judged):  # none (MAVROS, or no setpoint at all)
            return
        if not all(judged):
            setpoints = [e for e in setpoints if _ROUTE(e) == _JUDGED]
        if self._own_ids() is None:
            self._add_pending(setpoints)
            return
        first = first_of_each(_TARGET, setpoints)
        verdicts = [[("OFB607", self._judge(event))] for event in first.values()]
        if not commit_alike(self.episodes, "setpoints", setpoints, verdicts):
            self.replay(batch)

    def _add_pending(self, setpoints: list[Event]) -> None:
        """What ``on_event`` does with each of these setpoints while the ids are unknown."""
        if len(set(map(_TARGET, setpoints))) > 1:
            for event in setpoints:
                self._add_one(event)
            return
        first, last = setpoints[0], setpoints[-1]
        self._add_one(first)
        if last is not first:
            pending = self.pending[_TARGET(first)]
            pending.last_t = last.t
            pending.count += len(setpoints) - 1

    def _add_one(self, event: Event) -> None:
        assert isinstance(event, MavlinkTarget)
        target = (event.target_system, event.target_component)
        pending = self.pending.get(target)
        if pending is None:
            self.pending[target] = _Pending(event.t, event.where, event.t)
        else:
            pending.last_t = event.t
            pending.count += 1

    def _judge(self, event: Event) -> dict[str, Offence]:
        assert isinstance(event, MavlinkTarget)
        key = (event.target_system, event.target_component, self._own_ids())
        judged = self.judged.get(key)
        if judged is None:
            offence = self._offence(event.target_system, event.target_component)
            judged = self.judged[key] = {} if offence is None else {offence[0]: offence[1]}
        return judged

    def _offence(self, system: int, component: int) -> tuple[str, Offence] | None:
        ids = self._own_ids()
        assert ids is not None
        own_sys, own_comp = ids
        wrong = []
        if system not in (0, own_sys):
            wrong.append(f"target_system {system} (the vehicle is system {own_sys})")
        if component not in (0, own_comp):
            wrong.append(f"target_component {component} (the autopilot is component {own_comp})")
        if not wrong:
            return None
        return (
            f"{system}/{component}",
            Offence(
                f"setpoint addressed to {' and '.join(wrong)}: PX4 drops it silently, so it is "
                "neither a setpoint nor a keep-alive"
            ),
        )

    def _resolve_pending(self) -> None:
        pending, self.pending = self.pending, {}
        for (system, component), seen in sorted(pending.items(), key=lambda kv: kv[1].t):
            offence = self._offence(system, component)
            if offence is not None:
                span = (seen.t, seen.where, seen.last_t, seen.count)
                self.episodes.start("OFB607", "setpoints", offence[0], offence[1], span)

    def finish(self, t_end: float) -> None:
        self.episodes.finish()
        if not self.pending:
            return
        others = [v for v in self.ctx.info.vehicles if v.isdigit() and v != self.ctx.vehicle]
        if others and not self.autopilot_seen:
            for (system, component), seen in sorted(self.pending.items(), key=lambda kv: kv[1].t):
                if system == 0:
                    continue  # broadcast: whichever vehicle that is takes it
                self.ctx.report(
                    "OFB607",
                    f"setpoints addressed to system {system} component {component}, but the "
                    f"recording shows no vehicle with that id (vehicles: {', '.join(others)}): "
                    "PX4 drops them silently",
                    seen.t,
                    seen.where,
                    end=seen.last_t if seen.count > 1 else None,
                    short=f"setpoints for system {system} component {component}, which is not "
                    "in the recording: dropped",
                )
            return
        self.ctx.cannot_check(
            "OFB607",
            "needs the vehicle's own MAVLink messages (its HEARTBEAT) or the MAV_SYS_ID "
            "parameter, to know the system id the setpoints must address",
        )
