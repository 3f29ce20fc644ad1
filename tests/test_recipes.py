"""docs/contributing.md's recipes, each tried on a scratch copy of the repository: a rule added by
``scripts/add_rule.py`` is registered everywhere the tests look, a PX4 release record added to
``fuzzoff/releases.py`` passes the tests that read the release table with no other edit, and a
new recording format or vehicle type in a rule's page does not stop ``docs/rules/build.py``."""

from __future__ import annotations

import ast
import importlib.util
import json
import os
import re
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path
from types import ModuleType

import pytest

from fuzzoff.catalog import get_rule
from tests.helpers import ROOT

sys.path.insert(0, str(ROOT / "scripts"))
import add_rule  # scripts/ is no package
import refresh_expected

sys.path.insert(0, str(ROOT / "docs" / "rules"))
import build as docs_build

SCRATCH_IGNORE = shutil.ignore_patterns(
    ".git", ".venv", "build", ".pytest_cache", ".mypy_cache", ".ruff_cache", ".hypothesis",
    "__pycache__", "*.pyc",
)  # fmt: skip


def scratch_copy(tmp_path: Path) -> Path:
    """The repository's files as a checkout has them (``fuzzoff/_version.py`` included)."""
    copy = tmp_path / "repo"
    shutil.copytree(ROOT, copy, ignore=SCRATCH_IGNORE, symlinks=True)
    return copy


def run_in(copy: Path, *args: str, cache: Path) -> subprocess.CompletedProcess[str]:
    """``python ARGS`` in the copy, with the copy's fuzzoff (and catalog cache of its own)."""
    env = {**os.environ, "PYTHONPATH": str(copy), "XDG_CACHE_HOME": str(cache), "NO_COLOR": "1"}
    return subprocess.run(
        [sys.executable, *args], cwd=copy, env=env, capture_output=True, text=True, timeout=900
    )


def pytest_in(copy: Path, *args: str, cache: Path) -> subprocess.CompletedProcess[str]:
    return run_in(copy, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist", *args,
                  cache=cache)  # fmt: skip


# -- Add a rule ---------------------------------------------------------------------------------

PROBE = """
import json, sys
from fuzzoff.catalog import get_rule, sent_stream_rules
from fuzzoff.checks import load_all
code = sys.argv[1]
print(json.dumps({
    "checks": [cls.__name__ for cls in load_all() if code in cls.codes],
    "name": get_rule(code).name,
    "sent_stream": code in sent_stream_rules(),
}))
"""


def test_a_scaffolded_rule_is_registered_everywhere_and_only_its_finding_is_left(
    tmp_path: Path,
) -> None:
    copy = scratch_copy(tmp_path)
    cache = tmp_path / "cache"
    done = run_in(copy, "scripts/add_rule.py", "OFB599", "rover-new-thing", "--sent-stream",
                  cache=cache)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "wrote rules/OFB599.toml" in done.stdout
    assert "next:" in done.stdout
    probe = run_in(copy, "-c", PROBE, "OFB599", cache=cache)
    assert probe.returncode == 0, probe.stderr
    assert json.loads(probe.stdout) == {
        "checks": ["RoverNewThing"],
        "name": "rover-new-thing",
        "sent_stream": True,
    }
    page = run_in(copy, "-m", "fuzzoff.cli", "rule", "OFB599", cache=cache)
    assert page.returncode == 0 and "# rover-new-thing (OFB599)" in page.stdout
    assert "[OFB599](OFB599.md)" in (copy / "docs" / "rules" / "README.md").read_text()
    assert "[OFB599](rules/OFB599.md)" in (copy / "docs" / "rules-rover-mavlink.md").read_text()
    folder = copy / "corpora" / "rules_rover"
    bad = json.loads((folder / "ofb599_rover_new_thing.expected.json").read_text())
    good = json.loads((folder / "good_ofb599_rover_new_thing.expected.json").read_text())
    assert "OFB599" in [f["code"] for f in bad["findings"]] and good["clean"] == ["OFB599"]
    lint = run_in(copy, "-m", "ruff", "check", "--no-cache", "scripts", "fuzzoff/checks",
                  "corpora/rules_rover", cache=cache)  # fmt: skip
    assert lint.returncode == 0, lint.stdout
    # the tests that read the catalog, the checks, the docs and the corpus find it ...
    corpus_case = "tests/test_corpora.py::test_corpus_recording_gives_expected_findings"
    registered = pytest_in(
        copy,
        "tests/test_rule_coverage.py",
        "tests/test_rule_pages.py",
        "tests/test_catalog_examples.py::test_good_test_stream_stays_clean[OFB599]",
        "tests/test_catalog_examples.py::test_stream_profile_is_one_the_rule_applies_to[OFB599]",
        f"{corpus_case}[rules_rover/good_ofb599_rover_new_thing.expected.json]",
        cache=cache,
    )
    assert registered.returncode == 0, registered.stdout[-3000:]
    # ... and what is left to write fails: the bad case and the bad test stream want OFB599
    left = pytest_in(
        copy,
        f"{corpus_case}[rules_rover/ofb599_rover_new_thing.expected.json]",
        "tests/test_catalog_examples.py::test_bad_test_stream_gives_the_rule[OFB599]",
        cache=cache,
    )
    assert "2 failed" in left.stdout, left.stdout[-3000:]


def _module(path: Path) -> ModuleType:
    spec = importlib.util.spec_from_file_location(f"scaffolded_{path.parent.name}", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules[spec.name]
    return module


@pytest.mark.parametrize("corpus", sorted(add_rule.CORPORA))
def test_the_scaffold_fits_every_builder_that_takes_new_rules(corpus: str, tmp_path: Path) -> None:
    """Without running them: each builder, its cases inserted, still builds its case list, and
    the check module is a ``Check`` naming its code."""
    folder = add_rule.CORPORA[corpus].folder
    for part in ("rules", "fuzzoff/checks", f"corpora/{folder}"):
        shutil.copytree(ROOT / part, tmp_path / part, ignore=SCRATCH_IGNORE)
    written = add_rule.add_rule(tmp_path, "OFB698", "made-up-rule", corpus_name=corpus,
                                severity="error", build=False)  # fmt: skip
    toml, check, builder = written
    assert get_rule("OFB608").code  # the real catalog is untouched
    assert 'severity = "error"' in toml.read_text()
    tree = ast.parse(check.read_text())
    (cls,) = [node for node in tree.body if isinstance(node, ast.ClassDef)]
    assert cls.name == "MadeUpRule" and ast.unparse(cls.bases[0]) == "Check"
    assert "codes = ('OFB698',)" in ast.unparse(cls)
    module = _module(builder)
    cases = module.mcap_cases() if corpus == "rules" else module.cases()
    found = {case.name: case for case in cases}
    bad, good = found["ofb698_made_up_rule"], found["good_ofb698_made_up_rule"]
    assert [f[:2] for f in bad.findings] == [("OFB698", "error")]
    assert good.clean == ["OFB698"] and not good.findings


def test_the_scaffold_refuses_a_code_or_name_taken_and_leaves_nothing(tmp_path: Path) -> None:
    for part in ("rules", "fuzzoff/checks", "corpora/rules_mavlink"):
        shutil.copytree(ROOT / part, tmp_path / part, ignore=SCRATCH_IGNORE)
    before = sorted(p.name for p in (tmp_path / "rules").iterdir())
    with pytest.raises(add_rule.ScaffoldError, match="OFB608 is taken"):
        add_rule.add_rule(tmp_path, "OFB608", "another-name", build=False)
    with pytest.raises(add_rule.ScaffoldError, match="already has the name"):
        add_rule.add_rule(tmp_path, "OFB697", "setpoint-message-ignored", build=False)
    with pytest.raises(add_rule.ScaffoldError, match="not a rule name"):
        add_rule.add_rule(tmp_path, "OFB697", "Bad_Name", build=False)
    assert sorted(p.name for p in (tmp_path / "rules").iterdir()) == before


# -- Add a recording format, add a vehicle type ----------------------------------------------------


def test_the_overview_tables_take_a_format_and_a_vehicle_they_have_no_words_for() -> None:
    rule = replace(get_rule("OFB608"), formats=("tlog", "newformat"), vehicles=("mc", "boat"))
    assert docs_build.applies_to(rule) == "multicopter, boat, 1.14+, tlog, newformat only"


# -- A rule's findings in the corpora beyond its own cases ----------------------------------------


def test_refresh_expected_writes_a_rules_findings_in_the_recorded_corpora_only(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    corpora = tmp_path / "corpora"
    shutil.copytree(ROOT / "corpora" / "real", corpora / "real")
    (corpora / "stream").mkdir()
    for name in ("ofb105_good.tlog", "ofb105_good.expected.json"):
        shutil.copy(ROOT / "corpora" / "stream" / name, corpora / "stream" / name)
    recorded = corpora / "real" / "sample.expected.json"
    built = corpora / "stream" / "ofb105_good.expected.json"
    as_committed = json.loads(recorded.read_text())
    for path in (recorded, built):  # as before a rule was written: no OFB701, no OFB005
        spec = json.loads(path.read_text())
        spec["findings"] = [f for f in spec["findings"] if f["code"] not in ("OFB005", "OFB701")]
        path.write_text(json.dumps(spec, indent=2) + "\n")
    left = built.read_text()
    assert refresh_expected.main(["OFB005", "OFB701", "--corpora", str(corpora)]) == 1
    out = capsys.readouterr().out
    assert "updated real/sample.expected.json" in out
    assert "to do   stream/ofb105_good.expected.json" in out
    assert json.loads(recorded.read_text())["findings"] == [
        *[f for f in as_committed["findings"] if f["code"] != "OFB005"],
        {"code": "OFB005", "severity": "info", "time_s": None},
    ]
    assert built.read_text() == left  # a builder's file: its builder writes it
    built.write_text((ROOT / "corpora" / "stream" / "ofb105_good.expected.json").read_text())
    assert refresh_expected.main(["OFB005", "OFB701", "--corpora", str(corpora)]) == 0
    assert capsys.readouterr().out == ""


# -- Add a PX4 release ----------------------------------------------------------------------------

RELEASE_TESTS = (
    "tests/test_releases.py",
    "tests/test_rule_pages.py",
    "tests/test_config.py::test_a_px4_release_that_is_not_modelled_is_an_error",
    "tests/test_fuzz_cli_errors.py::test_a_px4_release_not_modelled_is_refused_as_lint_refuses_it",
)
"""The tests that read the release table. With a release added (and the docs built), the whole
suite failed only in test_releases, test_config and test_fuzz_cli_errors, which named 1.18 as the
newest release and 1.19 as one past it, until they read both from the table; test_rule_pages'
pattern of docs addresses stopped at 1.18."""


def add_release(releases_py: Path) -> str:
    """The recipe's one edit: ``V1_19 = replace(V1_18, ...)`` before ``MAIN``, in ``RELEASES``
    and ``PX4Profile``, ``MAIN`` pointed at it. Returns the new name."""
    text = releases_py.read_text()
    newest = re.findall(r"^(V1_(\d+)) = replace\(", text, re.M)[-1]
    old, minor = newest[0], int(newest[1])
    new, name = f"V1_{minor + 1}", f"1.{minor + 1}"
    record = (
        f'{new} = replace({old}, name="{name}", covers="v{name}: as 1.{minor}", '
        f"minors=({minor + 1},))\n\n"
    )
    edits = [
        (f'"1.{minor}", "main"]', f'"1.{minor}", "{name}", "main"]'),
        (f"MAIN = replace(\n    {old},", f"{record}MAIN = replace(\n    {new},"),
        (f"{old}, MAIN)", f"{old}, {new}, MAIN)"),
    ]
    for before, after in edits:
        assert text.count(before) == 1, before
        text = text.replace(before, after)
    releases_py.write_text(text)
    return name


def test_a_release_added_to_the_table_needs_no_other_edit(tmp_path: Path) -> None:
    copy = scratch_copy(tmp_path)
    cache = tmp_path / "cache"
    name = add_release(copy / "fuzzoff" / "releases.py")
    listed = run_in(copy, "-m", "fuzzoff.cli", "profiles", "--format", "json", cache=cache)
    assert [p["profile"] for p in json.loads(listed.stdout)["px4"]][-2:] == [name, "main"]
    built = run_in(copy, "docs/rules/build.py", cache=cache)  # the recipe's docs step
    assert built.returncode == 0, built.stderr
    assert f"1.18, {name}, main" in (copy / "docs" / "rules" / "OFB608.md").read_text()
    done = pytest_in(copy, *RELEASE_TESTS, cache=cache)
    assert done.returncode == 0, done.stdout[-3000:]
