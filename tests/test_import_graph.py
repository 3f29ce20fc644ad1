"""The import graph of ``fuzzoff/``: no circle, and no arrow from a layer back up to its caller
(issue 27). Every import counts, at module level, inside a function or under
``TYPE_CHECKING``: each is an arrow a reader of the code follows. The graph is read from the
source with ``ast``, so a circle fails here before it fails at import time."""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "fuzzoff"

RUNS_THEM = {
    "fuzzoff.commands": {"fuzzoff.cli", "fuzzoff.commands"},
    "fuzzoff.cli": set(),
    "fuzzoff.engine": {
        "fuzzoff",
        "fuzzoff.commands",
        "fuzzoff.engine",
        "fuzzoff.fleet",
        "fuzzoff.fuzz",
        "fuzzoff.gate_timeline",
        "fuzzoff.sitl",
    },
}
"""A module (or package) -> the only modules and packages that may import it: the commands are
the top (only the CLI runs them), and the engine is run by the commands, the fleet's tasks, the
fuzz campaigns and the SITL verdict, never by what it runs (readers, gate, checks, findings,
timelines, renderers)."""


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


MODULES = {module_name(p): p for p in PACKAGE.rglob("*.py")}


def _known(name: str) -> str:
    """The module ``name`` is in (``fuzzoff.engine.lint_file`` -> ``fuzzoff.engine``)."""
    while name not in MODULES:
        name = name.rpartition(".")[0]
    return name


def imported(module: str) -> Iterator[str]:
    """The fuzzoff modules ``module`` imports, anywhere in its source."""
    path = MODULES[module]
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*parent, *([base] if base else [])])
            names = [
                f"{base}.{a.name}" if f"{base}.{a.name}" in MODULES else base for a in node.names
            ]
        else:
            continue
        for name in names:
            if name == "fuzzoff" or name.startswith("fuzzoff."):
                yield _known(name)


GRAPH = {m: sorted(set(imported(m)) - {m}) for m in sorted(MODULES)}


def circles(graph: dict[str, list[str]]) -> list[list[str]]:
    """One circle (a path back to its start) for each strongly connected group (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    groups: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph.get(v, []):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                groups.append(group)

    for v in graph:
        if v not in index:
            visit(v)
    return [_circle_through(graph, set(group)) for group in groups]


def _circle_through(graph: dict[str, list[str]], group: set[str]) -> list[str]:
    """A shortest path from the group's first module back to it, inside the group."""
    start = min(group)
    paths = {start: [start]}
    frontier = [start]
    while frontier:
        following = []
        for v in frontier:
            for w in graph[v]:
                if w == start:
                    return [*paths[v], start]
                if w in group and w not in paths:
                    paths[w] = [*paths[v], w]
                    following.append(w)
        frontier = following
    return sorted(group)


def _within(module: str, names: set[str]) -> bool:
    """Is ``module`` one of ``names`` or inside one of them (``fuzzoff`` itself: its
    ``__init__`` only, the public API)?"""
    return any(module == n or (n != "fuzzoff" and module.startswith(n + ".")) for n in names)


def test_the_import_graph_has_no_circle() -> None:
    found = circles(GRAPH)
    assert not found, "import circles:\n" + "\n".join(" -> ".join(c) for c in found)


def test_no_module_imports_the_layer_that_runs_it() -> None:
    upward = [
        f"{module} imports {target}"
        for module, targets in GRAPH.items()
        for target in targets
        for layer, allowed in RUNS_THEM.items()
        if _within(target, {layer}) and not _within(module, allowed | {layer})
    ]
    assert not upward, "\n".join(upward)


def test_the_walk_finds_circles_and_the_imports_inside_functions() -> None:
    assert circles({"a": ["b"], "b": ["c"], "c": ["a", "d"], "d": []}) == [["a", "b", "c", "a"]]
    assert circles({"a": ["b"], "b": []}) == []
    # lint imports its fleet half only when a run needs it, inside ``run``
    assert "fuzzoff.commands._lint_fleet" in GRAPH["fuzzoff.commands.lint"]
