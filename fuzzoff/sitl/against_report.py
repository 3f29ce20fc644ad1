"""The report of a live campaign (``fuzzoff fuzz --against``): terminal and JSON."""

from __future__ import annotations

import json
from collections import Counter
from typing import Any

from fuzzoff.report.sanitize import printable
from fuzzoff.sitl.against import (
    AgainstConfig,
    AgainstResult,
    Disagreement,
    Example,
    describe_item,
)

STATUS_TEXT = {
    "agree": "agree",
    "differ": "differ",
    "outside": "outside the gate (PX4 changed mode or arming, or refused an arm, by itself first)",
    "noise": "noise (the host did not send the stream as meant)",
    "failed": "not run",
}


def _plural(n: int, word: str) -> str:
    return f"{n} {word}" + ("" if n == 1 else "s")


def to_terminal(result: AgainstResult) -> str:
    config = result.config
    search = result.search
    follow = len(result.examples) - len(search)
    lines = [
        f"fuzzoff fuzz --against sitl:{config.build.release} --vehicle {config.vehicle}"
        f" --transport {config.transport}, seed {config.seed}"
    ]
    boots = ", ".join(f"{b:.0f} s" for b in result.boots) or "-"
    lines.append(
        f"  PX4 {config.build.release} (instance {config.instance}): ready to arm {boots} after"
        f" start; {_plural(max(0, len(result.boots) - 1), 'restart')}"
    )
    mean = sum(e.seconds for e in search) / len(search) if search else 0.0
    lines.append(
        f"  streams       {len(search)} sent in {result.seconds:.0f} s ({mean:.0f} s each);"
        f" {_plural(follow, 'more run')} to confirm and shrink; {result.same_shape} drawn"
        " but not sent (the same to PX4's gate as one sent)"
    )
    counts: Counter[str] = Counter(e.status for e in search)
    lines.append(
        "  verdicts      "
        + ", ".join(f"{STATUS_TEXT[k]} {counts[k]}" for k in STATUS_TEXT if counts[k])
    )
    outcomes = result.outcomes()
    if outcomes:
        lines.append("  PX4 outcomes")
        width = max(len(k) for k in outcomes)
        for key, n in sorted(outcomes.items()):
            lines.append(f"    {printable(key):<{width}}  {n}")
    for number, case in enumerate(result.disagreements, 1):
        lines += _disagreement(number, case, config)
    for e in (e for e in search if e.status in ("outside", "noise")):
        lines.append(f"  {e.status}: stream {e.index}: {printable(e.reason)}")
    for e in (e for e in result.examples if e.status == "failed"):
        lines.append(f"  not run: stream {e.index}: {printable(e.reason)}")
    if result.stopped:
        lines.append(f"  stopped: {printable(result.stopped)}")
    confirmed = sum(1 for d in result.disagreements if d.confirmed)
    edges = sum(1 for d in result.disagreements if d.kept.edge)
    lines.append(
        f"{_plural(len(search), 'stream')} in {result.seconds:.0f} s; "
        + (
            f"{_plural(len(result.disagreements), 'disagreement')} ({confirmed} confirmed,"
            f" {edges} at the loss check's phase)"
            if result.disagreements
            else "PX4 and the gate model agreed on every stream judged"
        )
    )
    return "\n".join(lines) + "\n"


def _disagreement(number: int, case: Disagreement, config: AgainstConfig) -> list[str]:
    state = {True: "confirmed", False: "seen once (the second run agreed)", None: "unconfirmed"}
    head = f"  disagreement {number} (stream {case.found.index}, {state[case.confirmed]}"
    if case.shrunk_by:
        head += f"; shrunk in {case.shrink_runs} runs: {', '.join(case.shrunk_by)}"
    elif case.shrink_runs:
        head += f"; {case.shrink_runs} simpler variants agreed"
    lines = [head + ")"]
    if case.seen_again:
        streams = ", ".join(str(i) for i in case.seen_again)
        lines.append(f"    seen again in streams {streams} (not followed up again)")
    for item in case.kept.differing:
        lines.append(f"    {printable(describe_item(item), 300)}")
    if case.kept.edge:
        lines.append(f"    note: {case.kept.edge}")
    second = case.second
    if second is not None and not case.confirmed:
        again = "; ".join(describe_item(i) for i in second.differing) or second.reason or "agree"
        lines.append(
            f"    second run (stream {second.index}, {second.status}): {printable(again, 300)}"
        )
    if case.reproducer is not None:
        path = printable(str(case.reproducer))
        lines.append(f"    reproducer {path}")
        if config.transport == "ros2":  # its stream over DDS to a fresh PX4
            release = config.build.release
            again = f"fuzzoff sitl replay {path} --transport ros2 --release {release}"
        else:
            again = f"fuzzoff replay {path} --to udp:127.0.0.1:{14580 + config.instance}"
        lines.append(f"    again:     {again}")
    return lines


def _example(e: Example) -> dict[str, Any]:
    s = e.scenario
    return {
        "stream": e.index,
        "purpose": e.purpose,
        "status": e.status,
        "reason": e.reason or None,
        "events": len(s.events),
        "duration_s": round(s.duration, 3),
        "params": dict(sorted(s.params.items())),
        "seconds": round(e.seconds, 1),
        "delivery": None if e.delivery is None else e.delivery.to_json(),
        "edge": e.edge,
        "verdict": None if e.verdict is None else e.verdict.to_json(),
        "notes": e.notes,
    }


def _case(case: Disagreement) -> dict[str, Any]:
    return {
        "found_in_stream": case.found.index,
        "kept_stream": case.kept.index,
        "confirmed": case.confirmed,
        "shrink_runs": case.shrink_runs,
        "shrunk_by": case.shrunk_by,
        "seen_again_in_streams": case.seen_again,
        "differ": [i.to_json() for i in case.kept.differing],
        "second_run": None if case.second is None else _example(case.second),
        "edge": case.kept.edge,
        "reproducer": None if case.reproducer is None else str(case.reproducer),
    }


def to_json(result: AgainstResult) -> str:
    config = result.config
    search = result.search
    counts: Counter[str] = Counter(e.status for e in search)
    data = {
        "campaign": {
            "against": f"sitl:{config.build.release}",
            "transport": config.transport,
            "px4_build": str(config.build.folder),
            "instance": config.instance,
            "vehicle": config.vehicle,
            "judged_as": config.judged_as,
            "seed": config.seed,
            "budget_s": config.budget_s,
            "examples": config.examples,
            "shrink_runs": config.shrink_runs,
            "save_dir": None if config.save_dir is None else str(config.save_dir),
        },
        "px4": {"ready_after_s": [round(b, 1) for b in result.boots]},
        "seconds": round(result.seconds, 1),
        "streams_sent": len(search),
        "follow_up_runs": len(result.examples) - len(search),
        "same_shape_not_sent": result.same_shape,
        "verdicts": {k: counts[k] for k in STATUS_TEXT},
        "px4_outcomes": dict(sorted(result.outcomes().items())),
        "disagreements": [_case(c) for c in result.disagreements],
        "runs": [_example(e) for e in result.examples],
        "stopped": result.stopped,
    }
    return json.dumps(data, indent=2) + "\n"
