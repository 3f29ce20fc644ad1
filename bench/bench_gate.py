"""Gate model throughput (issue 6): events per second through ``GateModel.feed`` alone.

Streams of 1M events per profile: ROS 2 style (OffboardControlMode + TrajectorySetpoint at
100 Hz with a loss and a resume every 30 s) and MAVLink style (SET_POSITION_TARGET_LOCAL_NED
through the receiver model). Target: the model adds at most a few microseconds per event to a
lint run. Events are built before the clock starts.
"""

from __future__ import annotations

import time

from fuzzoff.events import (
    ControlMode,
    Event,
    SetPositionTargetLocal,
    TrajectorySetpoint,
    VehicleStatus,
)
from fuzzoff.gate import GateModel
from fuzzoff.profiles import Profile

N = 1_000_000


def _ros2(n: int) -> list[Event]:
    events: list[Event] = [VehicleStatus(t=0.0, nav_state=14, armed=True, user_intention=14)]
    for i in range(n // 2):
        t = i * 0.01
        if 20.0 < t % 30.0 < 22.0:  # a 2 s gap every 30 s: loss, failsafe, resume
            continue
        events.append(ControlMode(t=t, position=True))
        events.append(TrajectorySetpoint(t=t, position=(0.0, 0.0, -2.0)))
    return events


def _mavlink(n: int) -> list[Event]:
    events: list[Event] = [VehicleStatus(t=0.0, nav_state=14, armed=True)]
    for i in range(n):
        events.append(
            SetPositionTargetLocal(
                t=i * 0.01,
                type_mask=0x09F8,
                target_system=1,
                target_component=1,
                position=(0.0, 0.0, -2.0),
            )
        )
    return events


def _run(px4: str, events: list[Event]) -> tuple[float, int]:
    model = GateModel(Profile(px4=px4), {}, "1")
    start = time.perf_counter()
    count = 0
    for event in events:
        count += len(model.feed(event))
    count += len(model.finish(events[-1].t))
    return time.perf_counter() - start, count


def main() -> None:
    for name, build in (("ros2 OCM+trajectory", _ros2), ("mavlink LOCAL_NED", _mavlink)):
        events = build(N)
        for px4 in ("legacy", "1.13", "1.15", "main"):
            seconds, transitions = _run(px4, events)
            rate = len(events) / seconds
            print(
                f"{name:<20} {px4:<7} {len(events):>8} events  {seconds:6.2f} s  "
                f"{rate / 1e6:5.2f} M events/s  {1e6 / rate:5.2f} us/event  "
                f"{transitions} transitions",
                flush=True,
            )


if __name__ == "__main__":
    main()
