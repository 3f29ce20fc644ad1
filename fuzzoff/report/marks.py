"""What identifies a finding across reports and re-lints: its fingerprint (SARIF's
``partialFingerprints``, the JSON report's ``fingerprint``, baselines, GitLab), and its one-line
text for CI views. Apart from ``sarif`` so that a JSON lint does not load the SARIF writer."""

from __future__ import annotations

import hashlib
from collections import Counter

from fuzzoff.findings import Finding
from fuzzoff.report.sanitize import CI_TEXT_LIMIT, printable


def fingerprint(finding: Finding) -> str:
    """Stable over re-runs of the same recording: rule, vehicle, topic, time window (10 ms)."""
    topic = finding.where.topic if finding.where is not None else ""
    start = "file" if finding.time_s is None else f"{finding.time_s:.2f}"
    end = "" if finding.end_s is None else f"{finding.end_s:.2f}"
    key = "\0".join((finding.code, finding.vehicle, topic, start, end))
    return hashlib.sha256(key.encode()).hexdigest()[:32]


def marks(findings: list[Finding]) -> list[str]:
    """Each finding's ``partialFingerprints`` value: its ``fingerprint``, with ``:N`` on the
    Nth repeat of the same one in a recording (two findings of one rule at one time)."""
    seen: Counter[str] = Counter()
    out = []
    for finding in findings:
        key = fingerprint(finding)
        out.append(key + (f":{seen[key]}" if seen[key] else ""))
        seen[key] += 1
    return out


def message_text(finding: Finding) -> str:
    where = []
    if finding.time_s is not None:
        when = f"at {finding.time_s:.3f} s"
        if finding.end_s is not None:
            when += f" to {finding.end_s:.3f} s"
        where.append(when)
    if finding.vehicle:
        where.append(f"vehicle {finding.vehicle!r}")
    if finding.where is not None and finding.where.topic:
        where.append(f"on {finding.where}")
    suffix = f" ({', '.join(where)})" if where else " (whole recording)"
    # one line, no bidi overrides, bounded: CI views show it as the recording wrote it
    return printable(finding.message + suffix, CI_TEXT_LIMIT)
