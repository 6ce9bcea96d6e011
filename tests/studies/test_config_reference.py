"""docs/config-reference.md is generated from the config models: stale when it differs from a fresh generation."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from railopt.studies.catalog import discover_models
from railopt.studies.kind import discover_kinds
from railopt.studies.reference import reference_markdown

DOC = Path(__file__).resolve().parents[2] / "docs" / "config-reference.md"


def test_committed_reference_is_current():
    assert DOC.read_text() == reference_markdown(), (
        "docs/config-reference.md is stale: run `railopt reference --out docs/config-reference.md`")


def test_reference_documents_every_kind_and_catalog_model_with_types_and_defaults():
    text = reference_markdown()
    for name in discover_kinds():
        assert f"## Kind `{name}`" in text
    for name in discover_models():
        assert f"## Model `{name}`" in text
    # a few rows, whole: field, type, default, description
    assert "| `seed` | int | 0 | ≥ 0; at most 9223372036854775807 |" in text
    assert "| `n_starts` | int | 16 | > 0; at most 10000000 |" in text
    assert ('| `vehicle` | str | required | a bundled vehicle name (sd40-2, manchester-coach, single-wheelset) or a '
            'vehicle file path (relative to the study file) |') in text  # no default vehicle (issue 27, item 2)
    assert "| `mass_ratio` | float | required | absorber / primary mass (> 0, ≤ 10) |" in text


def test_reference_command_prints_the_same_text():
    done = subprocess.run([sys.executable, "-m", "railopt.studies.cli", "reference"], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout == reference_markdown()
