"""Every public definition of the four packages carries a docstring, read from the source (AST), not from an import.

The rule, applied to each module of ``railopt`` (``railopt/``), ``railopt.models`` (``models/``),
``railopt.design`` (``design/``) and ``railopt.studies`` (``studies/``), the folders of pyproject's package-dir:

* a module-level ``def``/``async def``/``class`` whose name does not start with ``_`` is public and needs a
  docstring — pydantic config models, dataclasses, protocols and exceptions included;
* inside a public class, every method whose name does not start with ``_`` needs one — properties, class
  methods, static methods and pydantic validators included (a property is an accessor with a contract: its
  unit and shape); dunder and private methods do not (their contract is the language's or the class's);
* ``@overload`` stubs are exempt (the implementation carries the docstring); nested classes and functions
  defined inside functions are not public API and are not checked; names bound by assignment
  (``X = ...``) have no place for a docstring and are not checked.

The extension points (what a new method, study kind or model plugs into) are checked first, in a test of their own.
"""

from __future__ import annotations

import ast
from pathlib import Path

from source_tree import source_modules

DEFS = (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)


MODULES = source_modules()


def _overload(node: ast.AST) -> bool:
    for d in getattr(node, "decorator_list", []):
        name = d.attr if isinstance(d, ast.Attribute) else getattr(d, "id", None)
        if name == "overload":
            return True
    return False


def _public(module: str, path: Path) -> dict[str, bool]:
    """``qualname -> has a docstring`` for the public definitions of one module."""
    tree = ast.parse(path.read_text(), str(path))
    found = {}
    for node in tree.body:
        if not isinstance(node, DEFS) or node.name.startswith("_") or _overload(node):
            continue
        found[node.name] = ast.get_docstring(node) is not None
        if isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef)) and not item.name.startswith("_") \
                        and not _overload(item):
                    found[f"{node.name}.{item.name}"] = ast.get_docstring(item) is not None
    return found


def _all_public() -> dict[str, bool]:
    return {f"{module}:{name}": ok for module, path in MODULES.items() for name, ok in _public(module, path).items()}


# each study kind's compute(config, context) and report(result, writer), wherever under studies/kinds/ they live
# (the campaign kind splits them: campaign.run:compute, campaign.report:report)
KIND_FUNCTIONS = sorted(f"{m}:{node.name}" for m in MODULES if m.startswith("railopt.studies.kinds.")
                        for node in ast.parse(MODULES[m].read_text()).body
                        if isinstance(node, ast.FunctionDef) and node.name in ("compute", "report"))

EXTENSION_POINTS = [
    "railopt.design.methods.base:Method",
    "railopt.design.methods.base:register",
    "railopt.studies.kind:StudyKind",
    "railopt.studies.kind:register_kind",
    "railopt.studies.kind:StudyContext",
    "railopt.studies.catalog:register_model",
    "railopt.studies.catalog.checks:Check",
    *KIND_FUNCTIONS,
]


def test_extension_points_have_docstrings():
    everything = _all_public()
    unknown = [name for name in EXTENSION_POINTS if name not in everything]
    assert not unknown, f"extension points not found (renamed or moved?): {unknown}"
    kinds = {name.rsplit(":", 1)[1] for name in KIND_FUNCTIONS}
    assert kinds == {"compute", "report"} and len(KIND_FUNCTIONS) >= 12, KIND_FUNCTIONS  # six kinds today
    missing = [name for name in EXTENSION_POINTS if not everything[name]]
    assert not missing, f"{len(missing)} extension point(s) without a docstring:\n" + "\n".join(missing)


def test_public_definitions_have_docstrings():
    everything = _all_public()
    assert len(everything) > 500, len(everything)
    missing = sorted(name for name, ok in everything.items() if not ok)
    assert not missing, (f"{len(missing)} of {len(everything)} public definitions without a docstring:\n"
                         + "\n".join(missing))


def _all_names(tree: ast.Module) -> list[str] | None:
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets):
            return [ast.literal_eval(e) for e in node.value.elts]
    return None


def test_one_all_convention_every_module_lists_its_public_definitions() -> None:
    """The ``__all__`` convention: every module that defines a public ``def``/``class`` declares ``__all__`` as
    one literal list; it names each of them, and each name it lists is bound in the module (a face module also
    lists the names it re-exports)."""
    import importlib

    missing, unlisted, unbound = [], [], []
    for module, path in MODULES.items():
        tree = ast.parse(path.read_text(), str(path))
        defined = [n.name for n in tree.body if isinstance(n, DEFS) and not n.name.startswith("_")]
        listed = _all_names(tree)
        if listed is None:
            if defined:
                missing.append(module)
            continue
        unlisted += [f"{module}.{name}" for name in defined if name not in listed]
        loaded = importlib.import_module(module)
        unbound += [f"{module}.{name}" for name in listed if not hasattr(loaded, name)]
    assert (missing, unlisted, unbound) == ([], [], [])
