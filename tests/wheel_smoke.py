"""Run by ``make test-lowest`` with the Python of a fresh virtual environment where only the built
wheel is installed (no Hypothesis), from a folder outside the source tree: what a user gets from
``pip install fuzzoff``. Exits non-zero naming the first thing that is wrong."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import sysconfig
from pathlib import Path

CORPORA = Path(sys.argv[1]).resolve()
FUZZOFF = [str(Path(sys.executable).with_name("fuzzoff"))]


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*FUZZOFF, *args], capture_output=True, text=True, timeout=300)


def expect(what: str, ok: bool, detail: object = "") -> None:
    print(f"{'ok  ' if ok else 'FAIL'} {what}")
    if not ok:
        raise SystemExit(f"wheel smoke test failed: {what}\n{detail}")


def main() -> None:
    spec = importlib.util.find_spec("fuzzoff")
    assert spec is not None and spec.origin is not None
    package = Path(spec.origin).parent
    expect(
        "fuzzoff is imported from the wheel",
        package.is_relative_to(sysconfig.get_paths()["purelib"]),
        package,
    )
    expect("py.typed is shipped", (package / "py.typed").is_file())
    expect("the rule catalog is shipped", any((package / "_catalog").glob("OFB*.toml")))
    expect("Hypothesis is not installed", importlib.util.find_spec("hypothesis") is None)
    recording = str(CORPORA / "tlog" / "stream_lost_in_offboard.tlog")
    lint = run("lint", recording, "--format", "json")
    expect("lint runs (exit 1: the recording has errors)", lint.returncode == 1, lint.stderr)
    page = Path("report.html").resolve()
    html = run("lint", recording, "--format", "html", "--output", str(page))
    text = page.read_text(encoding="utf-8") if page.exists() else ""
    expect(
        "the HTML report carries its plotting library and script",
        html.returncode == 1 and "uPlot" in text and "zoomable timelines" in text,
        html.stderr,
    )
    gate = run("gate", recording)
    expect("gate runs", gate.returncode == 0, gate.stderr)
    rule = run("rule", "OFB101")
    expect("rule runs", rule.returncode == 0 and "OFB101" in rule.stdout, rule.stderr)
    profiles = run("profiles")
    expect("profiles runs", profiles.returncode == 0, profiles.stderr)
    fuzz = run("fuzz", "--budget", "1")
    expect(
        "fuzz says in one line how to install what it needs",
        fuzz.returncode == 2
        and fuzz.stderr.count("\n") == 1
        and "pip install 'fuzzoff[fuzz]'" in fuzz.stderr,
        fuzz.stderr,
    )


if __name__ == "__main__":
    main()
