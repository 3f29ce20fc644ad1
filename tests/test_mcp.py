"""``fuzzoff mcp`` answers its four tools through the official MCP SDK's own client over stdio
(issue 30 item 4); skipped where the ``mcp`` extra is not installed."""

from __future__ import annotations

import json
import os
import sys
from typing import Any

import pytest

from tests.helpers import ROOT

pytest.importorskip("mcp")

import anyio
from mcp import ClientSession
from mcp.client.stdio import StdioServerParameters, stdio_client

RECORDING = "corpora/tlog/stream_lost_in_offboard.tlog"


def _text(result: Any) -> str:
    assert not result.is_error, result.content
    return "".join(c.text for c in result.content if c.type == "text")


async def _ask() -> dict[str, Any]:
    server = StdioServerParameters(
        command=sys.executable, args=["-m", "fuzzoff.cli", "mcp"], env=dict(os.environ), cwd=ROOT
    )
    answers: dict[str, Any] = {}
    async with stdio_client(server) as (read, write), ClientSession(read, write) as session:
        await session.initialize()
        tools = (await session.list_tools()).tools
        answers["tools"] = {t.name: t for t in tools}
        answers["lint"] = json.loads(_text(await session.call_tool("lint", {"path": RECORDING})))
        answers["gate"] = json.loads(_text(await session.call_tool("gate", {"path": RECORDING})))
        answers["rule"] = _text(await session.call_tool("rule", {"code": "OFB101"}))
        answers["rules"] = _text(await session.call_tool("rule", {}))
        answers["profiles"] = json.loads(_text(await session.call_tool("profiles", {})))
        answers["missing"] = await session.call_tool("lint", {"path": "no/such/flight.tlog"})
    return answers


def test_the_sdk_client_gets_the_four_tools_over_stdio() -> None:
    answers = anyio.run(_ask)
    tools = answers["tools"]
    assert set(tools) == {"lint", "gate", "rule", "profiles"}
    for tool in tools.values():
        assert tool.annotations.read_only_hint is True and tool.annotations.open_world_hint is False
    lint = answers["lint"]
    assert lint["tool"] == "fuzzoff" and lint["exit_status"] == 1
    (file,) = lint["files"]
    assert {"OFB101", "OFB103"} <= {f["code"] for f in file["findings"]}
    (vehicle,) = answers["gate"]["vehicles"]
    failsafe = [r for r in vehicle["timeline"] if r["what"] == "failsafe"]
    assert failsafe and failsafe[0]["see"] == "docs/gate.md#loss"
    assert answers["rule"].startswith("# keepalive-below-2hz (OFB101)")
    assert "OFB101 keepalive-below-2hz" in answers["rules"]
    assert "1.15" in {p["profile"] for p in answers["profiles"]["px4"]}
    assert answers["missing"].is_error
