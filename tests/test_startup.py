"""What starting ``fuzzoff`` loads (issue 31 item 1): a command imports only what it uses.

Not timed (the machine's load would make a timed test flaky): each test runs the command in a
fresh interpreter and lists the modules it left in ``sys.modules``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.helpers import ROOT

THIRD_PARTY = (
    "numpy",
    "pyulog",
    "rosbags",
    "mcap",
    "mcap_ros2",
    "pymavlink",
    "rich",
    "hypothesis",
    "dask",
    "distributed",
    "pyarrow",
    "fsspec",
)
"""Libraries no command needs before it reads a recording or prints a report."""

ENGINE = (
    "fuzzoff.fuzz",
    "fuzzoff.sitl",
    "fuzzoff.report",
    "fuzzoff.fleet",
    "fuzzoff.engine",
    "fuzzoff.gate",
    "fuzzoff.checks",
    "fuzzoff.catalog",
    "fuzzoff.config",
    "fuzzoff.formats",
    "fuzzoff.events",
    "fuzzoff.commands.",
)
"""fuzzoff's own machinery, which ``--version`` and ``--help`` never reach."""


def loaded_after(code: str) -> list[str]:
    """The modules a fresh interpreter holds after running ``code`` (standard output a pipe,
    nothing in the environment asking for a terminal's output)."""
    probe = (
        "import sys, json\n"
        f"{code}\n"
        "print(json.dumps(sorted(m for m in sys.modules if sys.modules[m] is not None)))\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("FORCE_COLOR", "TTY_COMPATIBLE")}
    result = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True, cwd=ROOT, env=env
    )
    modules: list[str] = json.loads(result.stdout.splitlines()[-1])
    return modules


def heavy(modules: list[str], prefixes: tuple[str, ...]) -> list[str]:
    return [
        m
        for m in modules
        if m.partition(".")[0] in prefixes or m.startswith(prefixes) or m in prefixes
    ]


def test_importing_the_cli_loads_nothing_the_version_does_not_need() -> None:
    modules = loaded_after("import fuzzoff.cli")
    assert heavy(modules, THIRD_PARTY + ENGINE) == []


def test_version_loads_nothing_it_does_not_print() -> None:
    code = (
        "from fuzzoff.cli import main\n"
        "try:\n"
        "    main(['--version'])\n"
        "except SystemExit as exc:\n"
        "    assert exc.code == 0, exc.code\n"
    )
    assert heavy(loaded_after(code), THIRD_PARTY + ENGINE) == []


def test_the_package_api_is_there_when_used() -> None:
    """``import fuzzoff`` stays cheap, and its names still resolve on first use."""
    modules = loaded_after("import fuzzoff")
    assert heavy(modules, THIRD_PARTY + ENGINE) == []
    import fuzzoff

    assert callable(fuzzoff.lint_file)
    assert fuzzoff.Settings(px4="1.15").px4 == "1.15"
    assert set(fuzzoff.__all__) <= set(dir(fuzzoff))


NOT_FOR_A_ULOG_LINT = (
    "rosbags",
    "mcap",
    "mcap_ros2",
    "pymavlink",
    "rich",
    "hypothesis",
    "dask",
    "distributed",
    "pyarrow",
    "fsspec",
    "fuzzoff.fuzz",
    "fuzzoff.sitl",
    "fuzzoff.fleet.",
    "fuzzoff.report.html",
    "fuzzoff.report.sarif",
    "fuzzoff.report.junit",
    "fuzzoff.report.terminal",
    "fuzzoff.formats.tlog.",
    "fuzzoff.formats.mcap.",
    "fuzzoff.formats.rosbag1.",
    "fuzzoff.formats.rosbag2.",
    "fuzzoff.formats.ros2msgs.",
    "numpy.ma.",
)
"""What a JSON lint of one ULog (a pre-commit hook's run) never reaches: the other formats'
readers and libraries, the fuzz, fleet and SITL machinery, the other reports."""


@pytest.mark.parametrize(
    "ulog",
    [
        ROOT / "corpora" / "real" / "sample_log_small.ulg",
        ROOT / "corpora" / "sitl" / "hold_with_unknown_sub_mode-1.16.2.ulg",
    ],
    ids=["real", "sitl"],
)
def test_a_one_file_lint_loads_only_its_reader_and_its_report(ulog: Path) -> None:
    code = (
        "import io, contextlib\n"
        "from fuzzoff.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    main(['lint', {str(ulog)!r}, '--format', 'json'])\n"
    )
    modules = loaded_after(code)
    assert "pyulog" in modules and "fuzzoff.report.json_report" in modules
    assert heavy(modules, NOT_FOR_A_ULOG_LINT) == []


def test_a_terminal_report_off_a_terminal_loads_no_rich() -> None:
    """The default report into a pipe or a file (a hook, CI) is plain text written without
    rich (``report/plain.py``); the rarely used parts of the lint path load on use."""
    ulog = ROOT / "corpora" / "real" / "sample_log_small.ulg"
    code = (
        "import io, contextlib\n"
        "from fuzzoff.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()) as out:\n"
        f"    main(['lint', {str(ulog)!r}])\n"
        "assert 'fuzzoff summary' in out.getvalue()\n"
    )
    modules = loaded_after(code)
    assert "fuzzoff.report.plain" in modules
    rarely = ("difflib", "fuzzoff.report.terminal", "fuzzoff.fuzz")
    assert heavy(modules, NOT_FOR_A_ULOG_LINT + rarely) == []


def test_the_cli_keeps_numpy_to_one_blas_thread_unless_told() -> None:
    """numpy's OpenBLAS starts a thread per core at import, half of numpy's import CPU; no
    command multiplies large matrices (issue 31). A number the user set is kept."""
    code = (
        "import os\n"
        "from fuzzoff.cli import main\n"
        "main(['profiles'])\n"
        "print(os.environ['OPENBLAS_NUM_THREADS'])\n"
    )
    base = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    for preset, expected in ((None, "1"), ("3", "3")):
        env = base if preset is None else {**base, "OPENBLAS_NUM_THREADS": preset}
        result = subprocess.run(
            [sys.executable, "-c", code],
            capture_output=True,
            text=True,
            check=True,
            cwd=ROOT,
            env=env,
        )
        assert result.stdout.splitlines()[-1] == expected
