"""Import one module file as it was at an earlier commit (``git show``), for A/B timings of a
change in the same run. The module's own imports resolve against the current tree, so this is
for files whose imports did not change in between."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import tempfile
from pathlib import Path
from types import ModuleType

import harness

REPO = harness.REPO


def module_at(commit: str, path: str) -> ModuleType:
    """The module at ``path`` (relative to the repository root) as of ``commit``."""
    shown = subprocess.run(
        ["git", "-C", str(REPO), "show", f"{commit}:{path}"], capture_output=True, text=True
    )
    if shown.returncode != 0:
        raise SystemExit(f"commit {commit} has no {path}")
    name = f"{Path(path).stem}_at_{commit}"
    file = Path(tempfile.mkdtemp()) / f"{name}.py"
    file.write_text(shown.stdout)
    spec = importlib.util.spec_from_file_location(name, file)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module
