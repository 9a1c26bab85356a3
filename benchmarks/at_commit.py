"""Earlier commits for A/B timings in the same run: one module file as it was (``git show``;
its own imports resolve against the current tree, so this is for files whose imports did not
change in between), or a whole tree installed in its own virtual environment, for timing whole
commands (:func:`python_at`); :func:`plugin_at` builds a plugin class of such a module with
its default parameters."""

from __future__ import annotations

import importlib.util
import site
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


def plugin_at(cls: type, **params: object) -> object:
    """An instance of ``cls``, a plugin class loaded from an earlier commit, with its default
    parameters updated by ``params``.

    Before the plugin API named the parameter schema ``PARAMS``, a plugin class declared it as
    ``params``; the current base class validates against ``PARAMS``, so an older class's
    schema is given that name first.
    """
    own = vars(cls)
    if "PARAMS" not in own and isinstance(own.get("params"), tuple):
        cls.PARAMS = own["params"]  # type: ignore[attr-defined]
    schema = cls.PARAMS  # type: ignore[attr-defined]
    return cls(**{**{p.name: p.default for p in schema}, **params})


def python_at(commit: str) -> Path:
    """The Python of a virtual environment holding the tree of ``commit`` installed in editable
    mode (its own entry points: plugins that moved since load from where they were), made once
    under ``benchmarks/out/at-COMMIT/``. It borrows this environment's packages (a ``.pth``
    file), so only tsrkit differs."""
    root = REPO / "benchmarks" / "out" / f"at-{commit}"
    python = root / "venv" / "bin" / "python"
    if python.exists():
        return python
    archive = subprocess.run(["git", "-C", str(REPO), "archive", commit], capture_output=True)
    if archive.returncode != 0:
        raise SystemExit(f"no commit {commit} in {REPO}")
    (root / "src").mkdir(parents=True, exist_ok=True)
    subprocess.run(["tar", "-x", "-C", str(root / "src")], input=archive.stdout, check=True)
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(root / "venv")], check=True)
    packages = subprocess.run(
        [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    (Path(packages) / "borrowed.pth").write_text("\n".join(site.getsitepackages()) + "\n")
    install = [sys.executable, "-m", "pip", "--python", str(python), "install", "-q"]
    subprocess.run(
        [*install, "--no-deps", "--no-build-isolation", "-e", str(root / "src")], check=True
    )
    return python
