"""What a ``pip install fuzzoff`` gives: lean (no Hypothesis) for everything but ``fuzz``, typed,
licensed, with bounded dependency ranges. ``make test-lowest`` checks the same from a built wheel
at the lowest versions allowed."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

from tests.helpers import CORPORA, ROOT

PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]

WITHOUT_HYPOTHESIS = """
import sys
sys.modules["hypothesis"] = None  # import hypothesis now fails as if it were not installed
from fuzzoff.cli import main
status = main(sys.argv[1:])
assert "hypothesis" not in {name.partition(".")[0] for name in sys.modules if sys.modules[name]}
sys.exit(status)
"""


def run_without_hypothesis(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", WITHOUT_HYPOTHESIS, *args],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
    )


RECORDING = str(CORPORA / "tlog" / "stream_lost_in_offboard.tlog")


@pytest.mark.parametrize(
    ("args", "status"),
    [
        (["lint", RECORDING, "--format", "json"], 1),
        (["lint", RECORDING, "--format", "html", "--output", "-"], 1),
        (["gate", RECORDING], 0),
        (["rule", "OFB101"], 0),
        (["profiles"], 0),
    ],
)
def test_commands_but_fuzz_run_without_hypothesis(args: list[str], status: int) -> None:
    result = run_without_hypothesis(*args)
    assert result.returncode == status, result.stderr
    assert result.stdout


def test_fuzz_without_hypothesis_says_how_to_install_it_in_one_line() -> None:
    result = run_without_hypothesis("fuzz", "--budget", "1")
    assert result.returncode == 2
    assert result.stderr == (
        "error: fuzzoff fuzz needs hypothesis, which a plain install leaves out: "
        "pip install 'fuzzoff[fuzz]'\n"
    )


def test_hypothesis_is_in_the_fuzz_extra_only() -> None:
    names = [re.split(r"[<>=\[ ]", r)[0].lower() for r in PROJECT["dependencies"]]
    assert "hypothesis" not in names
    assert any(r.startswith("hypothesis>=") for r in PROJECT["optional-dependencies"]["fuzz"])


def test_every_dependency_range_has_both_bounds() -> None:
    extras = PROJECT["optional-dependencies"]
    for requirement in [*PROJECT["dependencies"], *extras["fuzz"]]:
        assert re.fullmatch(r"[\w.-]+>=[\d.]+,<[\d.]+", requirement), requirement


def test_license_and_type_marker_ship() -> None:
    assert PROJECT["license"] == "Apache-2.0" and PROJECT["license-files"] == ["LICENSE"]
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert "Apache License" in text and "Version 2.0, January 2004" in text
    assert (ROOT / "fuzzoff" / "py.typed").is_file()
    assert "Typing :: Typed" in PROJECT["classifiers"]


def test_the_version_comes_from_the_tag(tmp_path: Path) -> None:
    """A wheel built at a tag carries the tag's version, in its metadata and in what
    ``fuzzoff --version`` prints (the generated ``fuzzoff/_version.py``): what the release
    workflow publishes and the Action installs (it sets the version from its ref the same way).
    The build is pip's, in isolation, from a copy of the source tree."""
    source = tmp_path / "src"
    shutil.copytree(
        ROOT, source, ignore=shutil.ignore_patterns(".venv", "build", ".git", "*cache*", "corpora")
    )
    env = {**os.environ, "SETUPTOOLS_SCM_PRETEND_VERSION": "9.8.7"}
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(tmp_path), str(source)],
        check=True,
        env=env,
        capture_output=True,
        timeout=600,
    )
    (wheel,) = tmp_path.glob("fuzzoff-*.whl")
    assert wheel.name.startswith("fuzzoff-9.8.7-")
    with zipfile.ZipFile(wheel) as archive:
        metadata = archive.read("fuzzoff-9.8.7.dist-info/METADATA").decode()
        generated = archive.read("fuzzoff/_version.py").decode()
    assert "\nVersion: 9.8.7\n" in metadata
    namespace: dict[str, object] = {}
    exec(generated, namespace)
    assert namespace["__version__"] == "9.8.7"
