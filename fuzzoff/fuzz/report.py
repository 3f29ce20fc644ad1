"""A campaign's result as terminal text, JSON, JUnit XML (one test case per property) or SARIF.

SARIF: one rule per property (``fuzz/<name>``), one result per counterexample, located at the
saved reproducer (an artifact, so code scanning shows it where it was committed).
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

from fuzzoff import __version__
from fuzzoff.fuzz.campaign import CampaignResult, PropertyResult
from fuzzoff.fuzz.known import KNOWN
from fuzzoff.report.sanitize import printable
from fuzzoff.report.sarif import BASE_ID, artifact_uri

SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"


def to_json(result: CampaignResult, saved: dict[str, Path], margins: list[Any]) -> str:
    cfg = result.config
    data: dict[str, Any] = {
        "tool": "fuzzoff",
        "version": __version__,
        "campaign": {
            "px4": cfg.px4,
            "vehicle": cfg.vehicle,
            "transport": cfg.transport,
            "seed": cfg.seed,
            "seeds": list(cfg.seeds) or [cfg.seed],
            "examples": cfg.examples,
            "budget_s": cfg.budget_s,
            "from": None if cfg.base is None else cfg.base.describe(),
            "from_problems": cfg.base_problems,
        },
        "failed": result.failed,
        "unchecked": result.unchecked,
        "examples": result.examples,
        "seconds": round(result.seconds, 3),
        "properties": [],
    }
    for r in result.results:
        entry = r.to_json()
        entry["reproducer"] = str(saved[r.name]) if r.name in saved else None
        data["properties"].append(entry)
    if margins:
        data["margins"] = [m.to_json() for m in margins]
    return json.dumps(data, indent=2) + "\n"


def to_junit(result: CampaignResult, saved: dict[str, Path]) -> str:
    failures = sum(1 for r in result.results if r.failed)
    suite = ET.Element(
        "testsuite",
        name=f"fuzzoff fuzz ({_seeds(result)})",
        tests=str(len(result.results)),
        failures=str(failures),
        errors="0",
        skipped=str(len(result.unchecked)),
        time=f"{result.seconds:.3f}",
    )
    for r in result.results:
        case = ET.SubElement(
            suite, "testcase", classname="fuzzoff.fuzz", name=r.name, time=f"{r.seconds:.3f}"
        )
        if r.failed:
            text = f"{r.failed_examples} of {r.examples} examples failed; the first:\n"
            text += "\n".join(r.problems)
            if r.counterexample is not None:
                text += f"\ncounterexample: {r.counterexample.describe()}"
            if r.name in saved:
                text += f"\nreproducer: {saved[r.name]}"
            failure = ET.SubElement(case, "failure", message=printable(r.problems[0], 300))
            failure.text = text
        elif r.examples == 0:
            ET.SubElement(case, "skipped", message="no example ran within the time budget")
        out = ET.SubElement(case, "system-out")
        out.text = f"{r.claim}: {r.examples} examples in {r.seconds:.2f} s"
        for pattern, count in r.known.items():
            out.text += f"\nleft out, a known problem of fuzzoff in {count} examples: "
            out.text += KNOWN.get(pattern, pattern)
    root = ET.Element("testsuites")
    root.append(suite)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def to_sarif(result: CampaignResult, saved: dict[str, Path], root: Path | None = None) -> str:
    root = (root or Path.cwd()).resolve()
    rules = [
        {
            "id": f"fuzz/{r.name}",
            "name": "".join(p.capitalize() for p in r.name.split("-")),
            "shortDescription": {"text": r.claim},
            "defaultConfiguration": {"level": "error"},
        }
        for r in result.results
    ]
    results = []
    for r in result.results:
        if not r.failed:
            continue
        item: dict[str, Any] = {
            "ruleId": f"fuzz/{r.name}",
            "level": "error",
            "message": {"text": "; ".join(r.problems)[:2000]},
            "properties": {
                "counterexample": None if r.counterexample is None else r.counterexample.describe(),
                "seed": result.config.seed,
            },
        }
        if r.name in saved:
            # As lint writes it: relative to the working folder (SRCROOT), percent-encoded.
            uri, base = artifact_uri(str(saved[r.name]), root)
            location = {"uri": uri, **({"uriBaseId": base} if base else {})}
            item["locations"] = [{"physicalLocation": {"artifactLocation": location}}]
        results.append(item)
    doc = {
        "$schema": SCHEMA,
        "version": "2.1.0",
        "runs": [
            {
                "tool": {
                    "driver": {
                        "name": "fuzzoff",
                        "version": __version__,
                        "rules": rules,
                    }
                },
                "originalUriBaseIds": {BASE_ID: {"uri": root.as_uri() + "/"}},
                "results": results,
            }
        ],
    }
    return json.dumps(doc, indent=2) + "\n"


def _seeds(result: CampaignResult) -> str:
    seeds = result.config.seeds
    if len(seeds) > 1:
        return f"seeds {seeds_text(seeds)} ({len(seeds)} campaigns)"
    return f"seed {result.config.seed}"


def seeds_text(seeds: tuple[int, ...]) -> str:
    """``0-199`` for a range, else the seeds with commas."""
    if seeds == tuple(range(seeds[0], seeds[0] + len(seeds))):
        return f"{seeds[0]}-{seeds[-1]}"
    return ",".join(str(s) for s in seeds)


def _line(r: PropertyResult) -> str:
    rate = f"{r.examples / r.seconds:.0f}/s" if r.seconds else "-"
    verdict = "FAILED" if r.failed else ("counted" if r.name == "docs-stricter" else "held")
    if not r.examples:
        verdict = "not run"
    return f"  {r.name:<14} {verdict:<8} {r.examples:>6} examples {r.seconds:7.2f} s {rate:>7}"


def to_terminal(result: CampaignResult, saved: dict[str, Path], margins: list[Any]) -> str:
    lines = [f"fuzzoff fuzz, {_seeds(result)}"]
    for problem in result.config.base_problems:
        lines.append(f"  --from incomplete, the part before this was fuzzed: {printable(problem)}")
    for r in result.results:
        lines.append(_line(r))
        if r.failed:
            shrunk = f", shrunk in {r.shrinks} steps" if r.shrinks else ""
            lines.append(
                f"      {r.failed_examples} of {r.examples} examples failed; the first "
                f"(example {r.found_after}){shrunk}:"
            )
        for p in r.problems:
            lines.append(f"      {printable(p, 300)}")
        if r.counterexample is not None:
            lines.append(f"      counterexample: {r.counterexample.describe()}")
        if r.name in saved:
            lines.append(f"      reproducer: {saved[r.name]}  (fuzzoff replay {saved[r.name]})")
        for pattern, count in r.known.items():
            what = KNOWN.get(pattern, pattern)
            lines.append(
                f"      left out: a known problem of fuzzoff in {count} examples "
                f"(--include-known to fail on it): {printable(what, 200)}"
            )
        for code, c in r.counts.items():
            lines.append(
                f"      {code}: fired {c['fired']}, gate accepted {c['gate_accepted']} "
                "(docs stricter than code)"
            )
    for m in margins:
        lines.append(f"  margin {m.family:<7} {m.describe()}")
    lines.append(f"{result.examples} examples in {result.seconds:.1f} s; {_verdict(result)}")
    return "\n".join(lines) + "\n"


def _verdict(result: CampaignResult) -> str:
    failed = sum(1 for r in result.results if r.failed)
    verdicts = [f"{failed} propert{'y' if failed == 1 else 'ies'} failed"] if failed else []
    if result.unchecked:
        verdicts.append(f"no example of {', '.join(result.unchecked)} ran")
    return "; ".join(verdicts) or "all held"
