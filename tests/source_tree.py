"""The package's source modules by dotted name, read from pyproject's package-dir folders (for the AST tests)."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LAYERS = {"railopt.models": ROOT / "models", "railopt.design": ROOT / "design", "railopt.studies": ROOT / "studies",
          "railopt": ROOT / "railopt"}


def source_modules() -> dict[str, Path]:
    """``{"railopt.models.system": Path(".../models/system.py"), ...}`` for every module of the four packages."""
    found = {}
    for package, folder in LAYERS.items():
        for path in sorted(folder.rglob("*.py")):
            rel = path.relative_to(folder).with_suffix("")
            parts = [p for p in rel.parts if p != "__init__"]
            found[".".join([package, *parts])] = path
    return found
