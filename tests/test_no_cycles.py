"""No import cycles anywhere in our packages: a module never needs, directly or through others,
a module that needs it. A cycle (a mixin importing its host, say) means neither side can be read,
tested or replaced alone.

The graph is read from the source with :mod:`ast`, without importing anything: every import
counts, at module level, under ``TYPE_CHECKING`` or inside a function (a lazy import is still a
dependency). ``from package import name`` points at ``package.name`` when that is a module, else
at ``package``; importing ``a.b`` points at ``a.b`` only (not at ``a``'s ``__init__``), as
import-linter's graph does.
"""

from __future__ import annotations

import ast
from collections.abc import Iterable, Mapping
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("basis", "fileio", "qos", "kiosk", "station")

#: cycles known and owned elsewhere, each with what breaks it; the test fails on any other cycle,
#: and on one of these once it is gone (strike it from here then)
KNOWN: dict[tuple[str, ...], str] = {}


def _modules() -> dict[str, Path]:
    """Every module of our packages by dotted name (a package by its own name)."""
    found: dict[str, Path] = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            found[".".join(parts)] = path
    return found


def _imported(module: str, path: Path, known: Mapping[str, Path]) -> set[str]:
    """The modules of ours that ``module`` (at ``path``) imports."""
    is_package = path.name == "__init__.py"
    targets: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = module.split(".") if is_package else module.split(".")[:-1]
                anchor = anchor[: len(anchor) - (node.level - 1)]
                base = ".".join(anchor + ([base] if base else []))
            names = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base for alias in node.names]
        else:
            continue
        for name in names:
            while name and name not in known:  # "kiosk.store.database.Store" -> "kiosk.store.database"
                name = name.rpartition(".")[0]
            if name and name != module:
                targets.add(name)
    return targets


def import_graph() -> dict[str, set[str]]:
    known = _modules()
    return {module: _imported(module, path, known) for module, path in known.items()}


def cycles(graph: Mapping[str, Iterable[str]]) -> list[list[str]]:
    """One cycle (a -> b -> ... -> a) through each strongly connected group of modules (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    groups: list[set[str]] = []

    def visit(start: str) -> None:  # iterative: the graph may be deep
        work = [(start, iter(sorted(graph.get(start, ()))))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, edges = work[-1]
            for nxt in edges:
                if nxt not in index:
                    index[nxt] = low[nxt] = len(index)
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(sorted(graph.get(nxt, ())))))
                    break
                if nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    group = set()
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        group.add(member)
                        if member == node:
                            break
                    if len(group) > 1:
                        groups.append(group)

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return [_a_cycle(graph, group) for group in groups]


def _a_cycle(graph: Mapping[str, Iterable[str]], group: set[str]) -> list[str]:
    """The shortest path from the group's first module back to itself, inside the group."""
    first = min(group)
    paths = {first: [first]}
    frontier = [first]
    while frontier:
        following = []
        for node in frontier:
            for nxt in sorted(graph.get(node, ())):
                if nxt == first:
                    return paths[node] + [first]
                if nxt in group and nxt not in paths:
                    paths[nxt] = paths[node] + [nxt]
                    following.append(nxt)
        frontier = following
    raise AssertionError(f"no cycle through {first} in {sorted(group)}")


def test_no_import_cycle_anywhere():
    found = [cycle for cycle in cycles(import_graph()) if tuple(cycle) not in KNOWN]
    assert not found, "import cycles:\n" + "\n".join(" -> ".join(cycle) for cycle in found)


def test_the_known_cycles_are_still_there():
    """A known cycle that was broken is struck from KNOWN, so it cannot come back unnoticed."""
    found = {tuple(cycle) for cycle in cycles(import_graph())}
    gone = [" -> ".join(cycle) for cycle in KNOWN if cycle not in found]
    assert not gone, "no longer cycles, strike them from KNOWN: " + "; ".join(gone)


def test_the_graph_sees_every_kind_of_import():
    """The reader finds plain, relative, TYPE_CHECKING and function-level imports (else the test
    above could pass on a graph with no edges)."""
    graph = import_graph()
    assert "kiosk.core.session.events" in graph["kiosk.core.session.core"]
    assert "kiosk.core.session.publishing" in graph["kiosk.core.qos_model"]
    assert "kiosk.core.session" in graph["kiosk.store.reading"]  # a package's own __init__
    assert sum(len(targets) for targets in graph.values()) > 500


def test_a_cycle_is_named_module_by_module():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set(), "e": {"e2"}, "e2": {"e"}}
    assert sorted(cycles(graph)) == [["a", "b", "c", "a"], ["e", "e2", "e"]]
    assert cycles({"a": {"b"}, "b": set()}) == []
