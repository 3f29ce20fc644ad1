"""Every rule in rules/ has a corpus recording that shows it and one that must stay clean of it.

A bad case is a ``corpora/**/NAME.expected.json`` whose ``findings`` contain the rule's code; a
good case lists the code in its optional ``clean`` key (the rule was exercised there and must
not fire; test_corpora.py enforces that, since every finding has to be listed). One failure
message names every rule that lacks either, so a missing case cannot hide behind another.
"""

from __future__ import annotations

import json
from pathlib import Path

from fuzzoff.catalog import load_catalog

CORPORA = Path(__file__).resolve().parent.parent / "corpora"


def _coverage() -> tuple[dict[str, list[str]], dict[str, list[str]]]:
    """code -> expected files that show it (bad), and that list it as clean (good)."""
    bad: dict[str, list[str]] = {}
    good: dict[str, list[str]] = {}
    for path in sorted(CORPORA.rglob("*.expected.json")):
        spec = json.loads(path.read_text())
        name = str(path.relative_to(CORPORA))
        for finding in spec.get("findings", []):
            bad.setdefault(finding["code"], []).append(name)
        for code in spec.get("clean", []):
            good.setdefault(code, []).append(name)
    return bad, good


def test_clean_lists_name_rules_that_exist_and_do_not_fire_there() -> None:
    catalog = load_catalog()
    problems = []
    for path in sorted(CORPORA.rglob("*.expected.json")):
        spec = json.loads(path.read_text())
        found = {f["code"] for f in spec.get("findings", [])}
        for code in spec.get("clean", []):
            if code not in catalog:
                problems.append(f"{path.name}: clean lists unknown rule {code}")
            elif code in found:
                problems.append(f"{path.name}: {code} is both expected and clean")
    assert not problems, "\n".join(problems)


def test_every_rule_has_a_bad_and_a_good_corpus_case() -> None:
    bad, good = _coverage()
    missing = []
    for code, rule in load_catalog().items():
        lacks = [kind for kind, cases in (("bad", bad), ("good", good)) if code not in cases]
        if lacks:
            missing.append(f"{code} ({rule.name}): no {' and no '.join(lacks)} case")
    assert not missing, (
        f"{len(missing)} rule(s) lack corpus cases (a bad case lists the code in `findings`, a "
        "good case in `clean` of its NAME.expected.json):\n" + "\n".join(missing)
    )
