"""Fixtures of the study tests."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

from railopt.models.vehicle import load_vehicle


@pytest.fixture(scope="module")
def sd40():
    """The bundled SD40-2 locomotive as its file defines it (read-only: tests derive variants from it)."""
    return load_vehicle("sd40-2")


_ROOT_CONFTEST = Path(__file__).resolve().parents[1] / "conftest.py"


def pytest_collect_file(file_path: Path, parent):
    """pytest imports every ``conftest.py`` as the module ``conftest``, so this file shadows tests/conftest.py
    for the test files of other folders that ``from conftest import …`` its helpers (collected after this
    folder).  Once pytest holds this module, put the root one back under that name."""
    current = sys.modules.get("conftest")
    if current is not None and Path(current.__file__).resolve() != _ROOT_CONFTEST:
        spec = importlib.util.spec_from_file_location("conftest", _ROOT_CONFTEST)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        sys.modules["conftest"] = module
