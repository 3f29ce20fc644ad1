"""``fuzzoff mcp`` without the ``mcp`` extra says how to add it (exit status 2), as ``fuzzoff
fuzz`` does for Hypothesis."""

from __future__ import annotations

import sys

import pytest

from tests.helpers import run_cli


def test_mcp_without_the_sdk_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "mcp", None)
    monkeypatch.setitem(sys.modules, "mcp.server", None)
    result = run_cli(["mcp"])
    assert result.returncode == 2
    assert "pip install 'fuzzoff[mcp]'" in result.stderr
