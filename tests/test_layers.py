"""The layer rules and the absence of import loops, read from the source (AST), not from a running import.

Every ``import`` and ``from … import`` counts, function-level (lazy) ones included; only imports under
``if TYPE_CHECKING:`` (annotations) do not.  A module importing a package depends on the package's
``__init__``; ``from package import name`` depends on the submodule when ``name`` is one.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from source_tree import ROOT, source_modules

MODULES = source_modules()


def _type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _imports(module: str, path: Path) -> set[str]:
    tree = ast.parse(path.read_text(), str(path))
    is_package = path.name == "__init__.py"
    targets: set[str] = set()

    def visit(node: ast.AST) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _type_checking(child):
                for other in child.orelse:
                    visit(other)
                continue
            if isinstance(child, ast.Import):
                targets.update(a.name for a in child.names)
            elif isinstance(child, ast.ImportFrom):
                base = child.module or ""
                if child.level:
                    anchor = module.split(".") if is_package else module.split(".")[:-1]
                    anchor = anchor[: len(anchor) - (child.level - 1)]
                    base = ".".join([*anchor, base] if base else anchor)
                for a in child.names:
                    sub = f"{base}.{a.name}"
                    targets.add(sub if sub in MODULES else base)
            visit(child)

    visit(tree)
    return {t for t in targets if t in MODULES and t != module}


GRAPH = {m: _imports(m, p) for m, p in MODULES.items()}


def _cycles() -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def strong(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in GRAPH[v]:
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(GRAPH):
        if v not in index:
            strong(v)
    return out


def test_the_graph_is_read() -> None:
    assert len(MODULES) > 60
    assert "railopt.models.system" in GRAPH["railopt.models.parametric"]


def test_no_import_loops() -> None:
    assert _cycles() == []


CORE = [m for m, path in MODULES.items() if path.parent == ROOT / "models" and path.name != "__init__.py"]


@pytest.mark.parametrize(("source", "forbidden"), [
    ("railopt.models", ("railopt.design", "railopt.studies")),
    ("railopt.design", ("railopt.models", "railopt.studies")),
    ("railopt.studies.output", ("railopt.studies.kinds",)),
])
def test_layer_rules(source: str, forbidden: tuple[str, ...]) -> None:
    broken = sorted((m, t) for m, targets in GRAPH.items() if m == source or m.startswith(source + ".")
                    for t in targets if any(t == f or t.startswith(f + ".") for f in forbidden))
    assert broken == []


def test_models_core_never_imports_the_vehicle_package() -> None:
    assert CORE, "the core modules of railopt.models were not found"
    broken = sorted((m, t) for m in CORE for t in GRAPH[m] if t.startswith("railopt.models.vehicle"))
    assert broken == []


KINDS = "railopt.studies.kinds"


def _kind(module: str) -> str | None:
    """The kind a module belongs to: ``railopt.studies.kinds.<kind>[.…]`` gives ``<kind>``; other modules None."""
    if not module.startswith(KINDS + "."):
        return None
    return module[len(KINDS) + 1:].split(".")[0]


def test_kinds_never_import_other_kinds() -> None:
    kinds = sorted({k for m in GRAPH if (k := _kind(m)) is not None})
    assert "campaign" in kinds and "ride" in kinds, "the kind modules were not found"
    broken = sorted((m, t) for m, targets in GRAPH.items() if _kind(m) is not None
                    for t in targets if _kind(t) is not None and _kind(t) != _kind(m))
    assert broken == []


def test_configs_never_import_the_adapter() -> None:
    configs = [m for m in GRAPH if m.startswith("railopt.studies.") and m.rsplit(".", 1)[1] in ("config", "specs")]
    assert {"railopt.studies.config", "railopt.studies.specs", "railopt.studies.kinds.campaign.config"} <= set(configs)
    broken = sorted((m, t) for m in configs for t in GRAPH[m]
                    if t == "railopt.studies.adapter" or t.startswith("railopt.studies.adapter."))
    assert broken == []
