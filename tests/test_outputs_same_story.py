"""Every output of a lint tells the same story (issue 26): asking for more reports, the HTML
report's plots among them, never changes what is judged. Each corpus folder is linted once with
only ``--format json`` and once with every format ``fuzzoff lint`` offers, each to its own file;
the two JSON reports must be identical, findings, stats and exit status alike. The same run
checks each machine-readable report against its consumer's schema (issue 30:
``tests/test_ci_formats.check_ci_reports``), so the corpus is linted once for both."""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import pytest

from fuzzoff.cli import build_parser
from tests.helpers import CORPORA, run_cli
from tests.test_ci_formats import CI_FORMATS, check_ci_reports

FOLDERS = sorted(p for p in CORPORA.iterdir() if p.is_dir() and p.name != "__pycache__")

SUFFIXES = {"json": "json", "html": "html", "sarif": "sarif", "junit": "xml", "terminal": "txt"}


def lint_formats() -> list[str]:
    """The ``--format`` choices ``fuzzoff lint --help`` lists."""
    with contextlib.redirect_stdout(io.StringIO()) as out, contextlib.suppress(SystemExit):
        build_parser("lint").parse_args(["lint", "--help"])
    found = re.search(r"--format \{([a-z0-9,-]+)\}", out.getvalue())
    assert found, out.getvalue()
    return found.group(1).split(",")


def test_every_lint_format_is_in_the_comparison() -> None:
    assert set(lint_formats()) >= {"json", "html", "sarif", "junit", "terminal", *CI_FORMATS}


@pytest.mark.parametrize("folder", FOLDERS, ids=[p.name for p in FOLDERS])
def test_more_outputs_give_the_same_json(folder: Path, tmp_path: Path) -> None:
    alone = tmp_path / "alone.json"
    plain = run_cli(["lint", str(folder), "--no-progress", "--format", "json", "-o", str(alone)])
    every = ["lint", str(folder), "--no-progress"]
    for fmt in lint_formats():
        out = tmp_path / ("dataset" if fmt == "parquet" else f"all.{SUFFIXES.get(fmt, fmt)}")
        every += ["--format", fmt, "-o", str(out)]
    together = run_cli(every)
    assert together.returncode == plain.returncode, together.stderr
    assert plain.returncode in (0, 1, 2), plain.stderr
    assert json.loads((tmp_path / "all.json").read_text()) == json.loads(alone.read_text())
    assert (tmp_path / "all.html").stat().st_size > 0
    written = {fmt: tmp_path / f"all.{SUFFIXES.get(fmt, fmt)}" for fmt in CI_FORMATS}
    check_ci_reports({fmt: path.read_text(encoding="utf-8") for fmt, path in written.items()})
