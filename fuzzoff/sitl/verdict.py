"""What PX4 did beside what the gate model predicts for that release.

The model runs on the client's tlog (what was sent, on PX4's clock: ``fuzzoff gate`` with the
release given), and its prediction is shifted onto PX4's boot time with the tlog's own
TIMESYNC/SYSTEM_TIME stamps. PX4's side comes from its ULog where there is one
(``truth.read_truth``), else from the same tlog (HEARTBEAT modes and COMMAND_ACKs).

Judged, item by item:

- every mode switch and arm or disarm the client sent: accepted or rejected (PX4's last ack);
- every offboard loss while armed in OFFBOARD: the time. PX4 checks the keep-alive at 10 Hz,
  so a loss falls in a *window* one check period long after ``newest keep-alive +
  COM_OF_LOSS_T``; the model's instant is judged against that window, and against PX4's own
  ``offboard_control_signal_lost`` flag where the ULog has it (the tlog has no flag: there the
  loss time is not judged, HEARTBEAT comes once a second);
- the failsafe action (the mode PX4 went to) and the automatic return to OFFBOARD.
"""

from __future__ import annotations

from dataclasses import field
from pathlib import Path
from typing import Any

from fuzzoff.config import load_settings
from fuzzoff.gate.params import GATE_PARAMS
from fuzzoff.lean_dataclass import dataclass
from fuzzoff.modes import custom_mode_to_nav_state, nav_state_name
from fuzzoff.sitl.truth import Mode, Truth, read_tlog, read_truth

CHECK_PERIOD_S = 0.1
"""Commander's health-check pass (gate.md#check-timing)."""
LOOP_S = 0.012
"""One Commander iteration (10 ms) and a logging tick: slack on each side of the window."""
LOSS_TOLERANCE_S = 0.11
"""The model's loss instant may differ from PX4's flag by up to one check period and a loop
(gate.md#check-timing: at least 110 ms)."""
DECISION_S = 0.05
"""The model decides a request at the time the tlog recorded it; PX4 logs it when its receiver
took it: a few milliseconds apart on the shifted clocks."""
MATCH_S = 0.6
"""A PX4 event and a model event this close are the same event."""
MODE_SETTLE_S = 0.5
"""PX4's mode after a loss is read this long after its flag (vehicle_status follows in 12 ms)."""
HEARTBEAT_SETTLE_S = 1.6
"""The same over a 1 Hz HEARTBEAT."""
NAV_OFFBOARD = 14
REQUESTS = {176: "switch", 400: "arm"}


@dataclass(frozen=True, slots=True)
class Item:
    what: str
    t: float
    """PX4's boot time in seconds."""
    px4: str
    model: str
    agree: bool | None
    """None: not judged (said why in ``note``)."""
    note: str = ""

    def to_json(self) -> dict[str, Any]:
        return {
            "what": self.what,
            "px4_time_s": round(self.t, 3),
            "px4": self.px4,
            "model": self.model,
            "agree": self.agree,
            "note": self.note,
        }


@dataclass(slots=True)
class Verdict:
    release: str
    source: str
    """Where PX4's side was read: ``ulog`` or ``tlog``."""
    items: list[Item] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)

    @property
    def agree(self) -> bool:
        return all(i.agree is not False for i in self.items)

    def to_json(self) -> dict[str, Any]:
        return {
            "release": self.release,
            "px4_side": self.source,
            "agree": self.agree,
            "items": [i.to_json() for i in self.items],
            "problems": self.problems,
        }


def model_rows(
    tlog: Path, release: str, params: dict[str, float], vehicle: str = "mc"
) -> tuple[list[dict[str, Any]], list[str]]:
    """The gate model's timeline for the autopilot in ``tlog`` (``fuzzoff gate``'s rows), for
    the vehicle PX4 flew (``fuzzoff.sitl.airframes``: a rover disarms anywhere)."""
    from fuzzoff.gate_timeline import gate_report

    overrides: dict[str, Any] = {"px4": release, "vehicle": vehicle}
    # as `fuzzoff gate --px4 RELEASE --vehicle V --param NAME=VALUE...` has them; a run may set
    # others the gate does not read (the tailsitter's FW_USE_AIRSPD)
    read = {
        name.upper(): float(value) for name, value in params.items() if name.upper() in GATE_PARAMS
    }
    if read:
        overrides["params"] = read
    settings = load_settings(Path.cwd(), overrides, per_recording=True)
    report, rows = gate_report(str(tlog), settings, controllers=False)
    vehicles = [v for v in rows if v != ""] or list(rows)
    mine = rows[vehicles[0]] if vehicles else []
    return [r for r in mine if r["source"] == "model"], list(report.problems)


def _request_label(command: int, param1: float, param2: float, param3: float) -> str:
    if command == 400:
        return "arm" if param1 >= 0.5 else "disarm"
    nav = custom_mode_to_nav_state((int(param2) & 0xFF) << 16 | (int(param3) & 0xFF) << 24)
    return f"switch to {nav_state_name(nav)}"


def _accepted(result: int | None) -> str:
    if result is None:
        return "no ack"
    return "accepted" if result == 0 else f"rejected ({result})"


DECISIONS = {
    "switch": frozenset({"request_accepted", "request_rejected", "mode"}),
    "arm": frozenset({"arm_accepted", "arm_rejected"}),
    "disarm": frozenset({"disarmed", "disarm_rejected"}),
}
"""The model's rows that answer each kind of request: an arm and a switch sent within a few
milliseconds of each other are each paired with their own answer, not the nearest row."""


def _model_decision(
    rows: list[dict[str, Any]], t: float, kind: str, used: set[int]
) -> dict[str, Any] | None:
    near = [
        r
        for r in rows
        if r["what"] in DECISIONS[kind]
        and abs(r["time_s"] - t) <= DECISION_S
        and id(r) not in used
        and "from the recording" not in r["message"]  # the model following, not deciding
    ]
    row = min(near, key=lambda r: abs(r["time_s"] - t)) if near else None
    if row is not None:
        used.add(id(row))
    return row


def _model_accepts(row: dict[str, Any]) -> bool:
    if row["what"] == "mode":  # a switch to another mode: refused where it gives a reason
        return not row.get("reason")
    return row["what"] in ("request_accepted", "arm_accepted", "disarmed")


def compare(
    tlog: Path,
    release: str,
    ulog: Path | None = None,
    params: dict[str, float] | None = None,
    client_sysid: int | None = None,
    vehicle: str = "mc",
) -> Verdict:
    params = params or {}
    view = read_tlog(tlog)
    verdict = Verdict(release, "ulog" if ulog is not None else "tlog")
    if view.offset is None:
        verdict.problems.append(f"{tlog}: no TIMESYNC or SYSTEM_TIME from PX4: times unknown")
        return verdict
    offset = view.offset
    rows, problems = model_rows(tlog, release, params, vehicle)
    verdict.problems += problems
    for r in rows:
        r["px4_t"] = r["time_s"] + offset
    truth: Truth = read_truth(ulog, client_sysid) if ulog is not None else view.truth
    if ulog is None:
        for request in truth.requests:
            object.__setattr__(request, "t", request.t + offset)
        truth.modes = [Mode(m.t + offset, m.nav_state, m.armed, None) for m in truth.modes]
        truth.keepalives = [k + offset for k in truth.keepalives]
    _requests(verdict, truth, rows)
    _stick_overrides(verdict, truth, rows)
    _losses(verdict, truth, rows, params.get("COM_OF_LOSS_T", 1.0), ulog is not None)
    _gate_disagreements(verdict, rows)
    verdict.items.sort(key=lambda i: i.t)
    return verdict


def _gate_disagreements(verdict: Verdict, rows: list[dict[str, Any]]) -> None:
    """``fuzzoff gate``'s own disagreements (recorded mode or ack vs the model) not already
    judged above."""
    judged = [i.t for i in verdict.items if i.agree is False or i.note.startswith("not judged")]
    for row in rows:
        if row["what"] != "disagreement":
            continue
        if any(abs(row["px4_t"] - t) <= 0.2 for t in judged):
            continue
        verdict.items.append(
            Item("recorded vs model", row["px4_t"], "as recorded", row["message"], False)
        )


def _requests(verdict: Verdict, truth: Truth, rows: list[dict[str, Any]]) -> None:
    shifted = [{**r, "time_s": r["px4_t"]} for r in rows]
    used: set[int] = set()
    for request in truth.requests:
        if request.command not in REQUESTS:
            continue
        label = _request_label(request.command, request.param1, request.param2, request.param3)
        kind = "switch" if request.command == 176 else label
        row = _model_decision(shifted, request.t, kind, used)
        px4 = _accepted(request.result)
        if row is None:
            verdict.items.append(
                Item(label, request.t, px4, "no decision", None, "the model does not judge it")
            )
            continue
        model_ok = _model_accepts(row)
        model = ("accepted" if model_ok else "rejected") + f": {row['message']}"
        agree = None if request.result is None else (request.result == 0) == model_ok
        note = _land_sample_lag(truth, request.t, label, row) if agree is False else ""
        if note:
            agree = None
        verdict.items.append(Item(label, request.t, px4, model, agree, note))


LAND_SAMPLE_S = 0.25
"""A tlog shows PX4's land detector only in EXTENDED_SYS_STATE, 5 Hz on these links: a change
of PX4's verdict this close before a request may not have reached the tlog yet."""
LAND_ANSWER_S = 0.05
"""PX4 answers a command in a Commander cycle after its stamp (acks 8-16 ms after it here): a
land verdict PX4 published in between is the one it acted on, and no recording of the
companion held it when the command was sent (seen over the ROS 2 bridge on main-2026-08-13:
the airplane counted landed just after the disarm's stamp, the plain disarm taken)."""


def _land_sample_lag(truth: Truth, t: float, label: str, row: dict[str, Any]) -> str:
    """Why a disarm the model judged from the recording's land detector cannot be judged: PX4's
    own land detector (ULog) changed to the verdict PX4 acted on within one EXTENDED_SYS_STATE
    period before the request, or between its stamp and PX4's answer, so the recording had
    not shown it yet ("" when that is not so)."""
    if label != "disarm" or "land detector:" not in row["message"]:
        return ""
    at = truth.landed_since(t + LAND_ANSWER_S)
    if at is None:
        return ""
    landed, since = at
    model_landed = _model_accepts(row)
    if landed == model_landed or t - since > LAND_SAMPLE_S:
        return ""
    state = "landed" if landed else "not landed"
    when = (
        f"{1000 * (t - since):.0f} ms before the disarm"
        if since <= t
        else f"{1000 * (since - t):.0f} ms after the disarm's stamp, before PX4 answered it"
    )
    return (
        f"not judged: PX4's land detector said {state} {when}, after the recording's last"
        " sample of it (a tlog's EXTENDED_SYS_STATE comes at 5 Hz)"
    )


STICK_OVERRIDE = "stick override"
NAV_POSCTL = 2
OVERRIDE_PAIR_S = 0.5
"""A model's stick override and PX4's leaving OFFBOARD for Position this close are one."""


def _stick_overrides(verdict: Verdict, truth: Truth, rows: list[dict[str, Any]]) -> None:
    """The sticks ending OFFBOARD (gate spec 16 S1): PX4's user intention going from OFFBOARD
    to Position, armed, with no request in the second before (a loss failsafe leaves the
    intention at OFFBOARD; a tlog's HEARTBEAT does not show it: judged from a ULog only),
    against the model's stick override rows."""
    if all(m.intention is None for m in truth.modes):
        return
    px4 = [
        m.t
        for prev, m in zip(truth.modes, truth.modes[1:], strict=False)
        if prev.intention == NAV_OFFBOARD
        and m.intention == NAV_POSCTL
        and m.armed
        and not any(0 <= m.t - r.t <= 1.0 for r in truth.requests)
    ]
    model = [r["px4_t"] for r in rows if r.get("reason") == STICK_OVERRIDE]
    for t in px4:
        near = [m for m in model if abs(m - t) <= OVERRIDE_PAIR_S]
        if near:
            model.remove(near[0])
            verdict.items.append(
                Item(STICK_OVERRIDE, t, "Position", "Position", True, f"{near[0] - t:+.3f} s")
            )
        else:
            verdict.items.append(Item(STICK_OVERRIDE, t, "Position", "OFFBOARD stays", False))
    for m in model:
        verdict.items.append(Item(STICK_OVERRIDE, m, "OFFBOARD stays", "Position", False))


def _px4_losses(truth: Truth, flagged: bool) -> list[float]:
    """Times PX4 lost the signal while armed in OFFBOARD: its flag, or the mode leaving
    OFFBOARD with no request (a tlog: HEARTBEAT)."""
    out = []
    if flagged:
        for t, lost in truth.loss_flag:
            mode = truth.mode_at(t)
            if lost and mode is not None and mode.armed and mode.nav_state == NAV_OFFBOARD:
                out.append(t)
        return out
    requested = [r.t for r in truth.requests]
    prev: Mode | None = None
    for mode in truth.modes:
        if (
            prev is not None
            and prev.nav_state == NAV_OFFBOARD
            and prev.armed
            and mode.armed
            and mode.nav_state != NAV_OFFBOARD
            and not any(0 <= mode.t - r <= HEARTBEAT_SETTLE_S for r in requested)
        ):
            out.append(mode.t)
        prev = mode
    return out


def _losses(
    verdict: Verdict, truth: Truth, rows: list[dict[str, Any]], timeout: float, flagged: bool
) -> None:
    model = [
        r
        for i, r in enumerate(rows)
        if r["what"] == "signal_lost"
        and any(f["what"] == "failsafe" and 0 <= f["px4_t"] - r["px4_t"] <= 0.05 for f in rows[i:])
    ]
    px4 = _px4_losses(truth, flagged)
    window = MATCH_S if flagged else HEARTBEAT_SETTLE_S
    paired = _pair(px4, model, window)
    used: set[int] = set()
    for t in px4:
        row_or_none = paired.get(t)
        match = [] if row_or_none is None else [row_or_none]
        # the newest keep-alive PX4 had before its flag (one logged at the flag's own
        # microsecond came with the check that flagged the loss, or after it)
        keepalive = truth.last_keepalive_before(t - KEEPALIVE_EPS_S)
        if not match:
            preempted = _preempted_loss(rows, t, window)
            if preempted is not None:
                _loss_time(verdict, t, preempted, keepalive, timeout, flagged)
                _px4_only(verdict, truth, t, flagged)
                continue
            verdict.items.append(Item("offboard loss", t, "lost", "no loss predicted", False))
            continue
        row = match[0]
        used.add(id(row))
        _loss_time(verdict, t, row, keepalive, timeout, flagged)
        _failsafe(verdict, truth, rows, t, row, flagged)
    for row in model:
        if id(row) not in used:
            verdict.items.append(
                Item("offboard loss", row["px4_t"], "no loss", f"lost: {row['message']}", False)
            )


KEEPALIVE_EPS_S = 0.0005


def _pair(
    px4: list[float], model: list[dict[str, Any]], window: float
) -> dict[float, dict[str, Any]]:
    """Each of PX4's losses with the model's nearest one within ``window``, nearest pairs
    first: with losses a few tenths of a second apart (COM_OF_LOSS_T 0.2 and a 4 Hz stream),
    taking the earliest in the window paired each with the next one's."""
    candidates = sorted(
        (abs(r["px4_t"] - t), t, i)
        for t in px4
        for i, r in enumerate(model)
        if abs(r["px4_t"] - t) <= window
    )
    paired: dict[float, dict[str, Any]] = {}
    taken: set[int] = set()
    for _, t, i in candidates:
        if t not in paired and i not in taken:
            paired[t] = model[i]
            taken.add(i)
    return paired


PREEMPTED = (
    "not judged: PX4's mode change reached the model before its own 10 Hz check, and the model"
    " followed it as an unseen mode change instead of predicting the action"
)


def _px4_only(verdict: Verdict, truth: Truth, t: float, flagged: bool) -> None:
    """The action and return PX4 took after a loss the model did not act on (preempted)."""
    settle = MODE_SETTLE_S if flagged else HEARTBEAT_SETTLE_S
    after = _px4_action(truth, t, settle)
    verdict.items.append(Item("failsafe action", t, _action_name(after), "-", None, PREEMPTED))
    later = [m for m in truth.modes if m.t > (after.t if after else t) + 0.001]
    back = bool(later) and later[0].nav_state == NAV_OFFBOARD and later[0].armed
    px4 = "back to OFFBOARD" if back else "stays"
    verdict.items.append(Item("automatic return", later[0].t if later else t, px4, "-", None))


def _px4_action(truth: Truth, t: float, settle: float) -> Mode | None:
    """PX4's failsafe action after its loss at ``t``: the first mode other than OFFBOARD, or
    a disarm (COM_OBL_RC_ACT 7 disarms and leaves the mode as it was)."""
    return next(
        (
            m
            for m in truth.modes
            if t - 0.001 <= m.t <= t + settle and (m.nav_state != NAV_OFFBOARD or not m.armed)
        ),
        None,
    )


def _action_name(mode: Mode | None) -> str:
    if mode is None:
        return "unknown"
    return "disarmed" if not mode.armed else nav_state_name(mode.nav_state)


def _preempted_loss(rows: list[dict[str, Any]], t: float, window: float) -> dict[str, Any] | None:
    """A model loss without a failsafe because the recording's mode change came first: a
    ``mode`` row taken from the recording (no command for it) at most one check period and a
    loop before the model's ``signal_lost``. The model then follows the recording instead of
    predicting the action (gate.md#check-timing: PX4's check has its own phase), so neither the
    action nor the return can be judged."""
    for i, row in enumerate(rows):
        if row["what"] != "signal_lost" or abs(row["px4_t"] - t) > window:
            continue
        before = [
            r
            for r in rows[:i]
            if r["what"] == "mode"
            and "from the recording" in r["message"]
            and 0 <= row["px4_t"] - r["px4_t"] <= CHECK_PERIOD_S + LOOP_S
        ]
        if before:
            return row
    return None


def _loss_time(
    verdict: Verdict,
    t: float,
    row: dict[str, Any],
    keepalive: float | None,
    timeout: float,
    flagged: bool,
) -> None:
    model_t = row["px4_t"]
    if not flagged:
        verdict.items.append(
            Item(
                "loss time",
                t,
                "seen over HEARTBEAT (1 Hz)",
                f"{model_t:.3f} s",
                None,
                "not judged: the tlog has no loss flag, HEARTBEAT comes once a second",
            )
        )
        return
    if keepalive is None:
        verdict.items.append(
            Item(
                "loss time",
                t,
                f"{t:.3f} s",
                f"{model_t:.3f} s",
                None,
                "no keep-alive logged before it",
            )
        )
        return
    start, end = keepalive + timeout, keepalive + timeout + CHECK_PERIOD_S
    inside = start - LOOP_S <= t <= end + LOOP_S and abs(model_t - t) <= LOSS_TOLERANCE_S
    verdict.items.append(
        Item(
            "loss time",
            t,
            f"{t - keepalive:.3f} s after the newest keep-alive (PX4's flag)",
            f"{model_t - keepalive:.3f} s; window {timeout:.2f}-{timeout + CHECK_PERIOD_S:.2f} s"
            " (one 10 Hz check period)",
            inside,
            f"model {1000 * (model_t - t):+.0f} ms from PX4's flag",
        )
    )


def _failsafe(
    verdict: Verdict,
    truth: Truth,
    rows: list[dict[str, Any]],
    t: float,
    row: dict[str, Any],
    flagged: bool,
) -> None:
    failsafe = next(
        (f for f in rows if f["what"] == "failsafe" and 0 <= f["px4_t"] - row["px4_t"] <= 0.05),
        None,
    )
    settle = MODE_SETTLE_S if flagged else HEARTBEAT_SETTLE_S
    after = _px4_action(truth, t, settle)
    px4_action = _action_name(after)
    model_action = "unknown"
    if failsafe is not None:
        disarm = failsafe.get("action") == "DISARM"
        model_action = "disarmed" if disarm else nav_state_name(failsafe["nav_state"])
    verdict.items.append(
        Item(
            "failsafe action",
            t,
            px4_action,
            f"{model_action}: {failsafe['message'] if failsafe else ''}",
            px4_action == model_action,
        )
    )
    back_model = next(
        (
            r
            for r in rows
            if r["px4_t"] > row["px4_t"]
            and r["what"] in ("offboard_resumed", "mode", "request_accepted")
        ),
        None,
    )
    model_returns = back_model is not None and back_model["what"] == "offboard_resumed"
    failsafe_t = after.t if after else t
    later = [m for m in truth.modes if m.t > failsafe_t + 0.001]
    px4_returns = bool(later) and later[0].nav_state == NAV_OFFBOARD and later[0].armed
    agree: bool | None = px4_returns == model_returns
    note = ""
    if (
        model_returns
        and not px4_returns
        and back_model is not None
        and later
        and not later[0].armed
        and abs(later[0].t - back_model["px4_t"]) <= CHECK_PERIOD_S + LOOP_S
    ):
        # the stream came back in the Commander cycle that disarmed: PX4's next status is
        # already disarmed (the failsafe cleared by the disarm, or still shown for one status),
        # so whether PX4 would have returned cannot be read from it
        agree = None
        note = (
            "not judged: PX4 disarmed in the cycle the stream came back"
            f" ({1000 * (later[0].t - back_model['px4_t']):+.0f} ms)"
        )
    verdict.items.append(
        Item(
            "automatic return",
            later[0].t if later else t,
            "back to OFFBOARD"
            if px4_returns
            else f"stays ({nav_state_name(later[0].nav_state) if later else 'end'})"
            + ("" if not later or later[0].armed else ", disarmed"),
            "back to OFFBOARD" if model_returns else "no return",
            agree,
            note,
        )
    )


def render(verdict: Verdict) -> str:
    lines = [f"PX4 {verdict.release} (read from its {verdict.source}) beside the gate model:"]
    for item in verdict.items:
        mark = {True: "agree ", False: "DIFFER", None: "  -   "}[item.agree]
        line = f"  {mark} {item.t:8.3f} s  {item.what:<18} PX4: {item.px4:<28} model: {item.model}"
        if item.note:
            line += f"  ({item.note})"
        lines.append(line)
    if not verdict.items:
        lines.append("  nothing to compare (no request, no loss)")
    for p in verdict.problems:
        lines.append(f"  note: {p}")
    lines.append(
        "verdict: PX4 and the model agree" if verdict.agree else "verdict: PX4 and the model DIFFER"
    )
    return "\n".join(lines) + "\n"
