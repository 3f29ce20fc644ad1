"""Where the gate model's reasoning is written for users: the sections of docs/gate.md, by
stable anchor (``<a id="loss">``), which ``fuzzoff gate``, ``fuzzoff fuzz`` and the code's
comments cite as ``gate.md#loss``.

A transition keeps the number of the section of PX4's behaviour it implements (``spec``, as the
model's authors numbered it); ``anchor`` turns it into the docs/gate.md section that explains
that behaviour to a user."""

from __future__ import annotations

DOC = "docs/gate.md"

ANCHORS: dict[str, str] = {
    "2.1.3": "check-timing",
    "4.3": "acks",
    "13a": "seen-on-px4",
    "2": "signal",
    "3": "before-switch",
    "4": "requests",
    "5": "loss",
    "6": "receiver",
    "7": "control-mode",
    "8": "multicopter",
    "9": "fixed-wing",
    "10": "rover",
    "11": "status",
    "12": "history",
    "13": "params",
    "14": "docs-vs-code",
    "15": "unverified",
    "16": "drift",
}
"""Section number (or its first part) -> anchor of docs/gate.md."""


def anchor(spec: str) -> str:
    """The docs/gate.md anchor for a section number (``5.1`` -> ``loss``); empty for none."""
    key = spec.strip()
    while key:
        if key in ANCHORS:
            return ANCHORS[key]
        key = key.rpartition(".")[0]
    return ""


def cite(spec: str) -> str:
    """``gate.md#loss``: what a terminal line shows; empty for an unknown section."""
    found = anchor(spec)
    return f"gate.md#{found}" if found else ""


def link(spec: str) -> str | None:
    """``docs/gate.md#loss``: the path in the repository, for machine-readable output."""
    found = anchor(spec)
    return f"{DOC}#{found}" if found else None
