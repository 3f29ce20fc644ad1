"""Write today's findings of some rules into the expected findings of the recorded corpora.

    .venv/bin/python scripts/refresh_expected.py OFB204 [OFB205 ...]

A new rule (or a changed one) fires in recordings beyond its own corpus cases, and every
``corpora/**/NAME.expected.json`` lists every finding of its recording (tests/test_corpora.py).
The corpora written by a builder (``corpora/FOLDER/build.py``) take the finding in the builder,
which writes their expected files again; the others, recordings made elsewhere (real PX4 logs,
PX4 SITL runs, fuzz reproducers: ``RECORDED``), have no builder, and this script updates them:
it lints each recording as the test does and puts today's findings of the given codes in place
of the ones listed (the other findings, and every other key, stay as they are; the exit status
follows the findings). A code listed under ``clean`` that now fires is left for a person to judge.

For the builders' corpora it writes nothing and lists the expected files whose findings of the
codes differ from today's: add the findings to their builders and run them.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
RECORDED = ("real", "sitl", "fuzz")
"""The corpus folders whose expected findings no builder writes (fuzz: the reproducers
``corpora/fuzz/build.py`` does not make again, and the kept ones)."""


def lint(recording: Path, args: Sequence[str]) -> tuple[int, list[dict[str, Any]]]:
    """``fuzzoff lint RECORDING --format json ARGS``: its exit status and findings."""
    from fuzzoff.cli import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        status = main(["lint", str(recording), "--format", "json", *args])
    (report,) = json.loads(out.getvalue())["files"]
    findings: list[dict[str, Any]] = report["findings"]
    return status, findings


def _listed(finding: dict[str, Any], with_vehicle: bool) -> dict[str, Any]:
    out = {k: finding[k] for k in ("code", "severity", "time_s")}
    if with_vehicle and finding.get("vehicle"):
        out["vehicle"] = finding["vehicle"]
    return out


def refresh(path: Path, codes: set[str], write: bool) -> str | None:
    """What changed in ``path`` (None: nothing); written when ``write``."""
    spec = json.loads(path.read_text(encoding="utf-8"))
    status, found = lint(path.parent / spec["recording"], spec.get("args", []))
    with_vehicle = any("vehicle" in f for f in spec["findings"])
    today = [_listed(f, with_vehicle) for f in found if f["code"] in codes]
    listed = [f for f in spec["findings"] if f["code"] in codes]
    if _same(listed, today):
        return None
    fired = sorted(codes & set(spec.get("clean", [])) & {f["code"] for f in today})
    if fired:
        return f"{', '.join(fired)} listed clean but fires now: judge it by hand"
    if write:
        kept = [f for f in spec["findings"] if f["code"] not in codes]
        spec["findings"] = kept + today
        spec["exit_status"] = status
        path.write_text(json.dumps(spec, indent=2) + "\n", encoding="utf-8")
    return f"{len(listed)} finding(s) of {', '.join(sorted(codes))} listed, {len(today)} today"


def _same(listed: list[dict[str, Any]], today: list[dict[str, Any]]) -> bool:
    from fuzzoff.commands.replay import compare

    return not compare(listed, today)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="scripts/refresh_expected.py",
        description="Put today's findings of the given rules in the recorded corpora's "
        "expected findings; list the builders' expected files that differ.",
    )
    parser.add_argument("codes", nargs="+", metavar="CODE")
    parser.add_argument("--corpora", type=Path, default=ROOT / "corpora", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    codes = {c.upper() for c in args.codes}
    stale = 0
    for path in sorted(args.corpora.rglob("*.expected.json")):
        recorded = path.relative_to(args.corpora).parts[0] in RECORDED
        change = refresh(path, codes, write=recorded)
        if change is None:
            continue
        where = path.relative_to(args.corpora)
        if recorded and "by hand" not in change:
            print(f"updated {where}: {change}")
        else:
            stale += 1
            print(f"to do   {where}: {change}")
    if stale:
        print(f"{stale} expected file(s) left: a builder's cases (then run it) or a judgement")
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
