"""Shared fixtures: where the real datasets live, and a clean plugin registry per test."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def shared_datasets_dir() -> Path:
    """``$TSRKIT_DATA_DIR`` or ``../shared/datasets`` beside the repository."""
    return Path(os.environ.get("TSRKIT_DATA_DIR", REPO.parent / "shared" / "datasets"))


@pytest.fixture(scope="session")
def shared_datasets() -> Path:
    """The real annotated datasets (CI has them beside the clone; their absence is an error)."""
    path = shared_datasets_dir()
    if not (path / "README.md").is_file():
        pytest.fail(f"real datasets not found at {path}; set TSRKIT_DATA_DIR")
    return path


@pytest.fixture
def registry(monkeypatch):
    """A fresh process-wide registry for the test, discarded afterwards."""
    from tsrkit.plugin import registry as reg

    reg.reset_registry()
    yield reg.get_registry()
    reg.reset_registry()
