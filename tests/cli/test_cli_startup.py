"""Lazy start-up: ``tsrkit --help`` lists every verb without importing the
verbs, NumPy, OpenCV or the plugins; a verb loads when it runs.

Timings: ``benchmarks/bench_startup.py``.
"""

import subprocess
import sys

import click
from click.testing import CliRunner

import tsrkit
from tsrkit.cli.main import cli
from tsrkit.cli.verbs import VERBS

HEAVY = ("numpy", "cv2", "matplotlib", "sklearn", "dask", "skimage", "tsrkit.plugin.registry")


def test_help_imports_no_verb_and_no_heavy_library():
    code = (
        "import sys\n"
        "from tsrkit.cli.main import cli\n"
        "cli.main(['--help'], prog_name='tsrkit', standalone_mode=False)\n"
        f"print([m for m in {HEAVY!r} if m in sys.modules])\n"
        "print([v.module for v in __import__('tsrkit.cli.verbs').cli.verbs.VERBS.values()"
        " if v.module in sys.modules])\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    lines = out.strip().splitlines()
    assert lines[-2:] == ["[]", "[]"]
    assert all(f"  {name}" in out for name in VERBS)


def test_loading_every_plugin_imports_no_map_reader():
    # sun-pca needs GPS tracks, not the OpenStreetMap reader and its SciPy graph routines
    code = (
        "import sys\n"
        "from tsrkit.plugin.registry import get_registry\n"
        "get_registry()\n"
        "print([m for m in ('tsrkit.geo.osm', 'tsrkit.geo.vicinity', 'scipy.sparse.csgraph')"
        " if m in sys.modules])\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip().splitlines()[-1] == "[]"


def test_each_listed_summary_is_the_verbs_own_first_sentence():
    for name, verb in VERBS.items():
        command = cli.get_command(click.Context(cli), name)
        assert command is not None
        assert command.get_short_help_str(1000) == verb.summary, name


def test_a_verb_loads_when_it_runs_and_unknown_verbs_still_fail_clearly():
    result = CliRunner().invoke(cli, ["presets"])
    assert result.exit_code == 0 and "recommended" in result.output
    result = CliRunner().invoke(cli, ["no-such-verb"])
    assert result.exit_code == 2 and "No such command 'no-such-verb'" in result.output


def test_the_python_api_names_resolve_on_first_use():
    assert tsrkit.Detector.__name__ == "Detector"
    assert tsrkit.select.__name__ == "build"
    from tsrkit import Candidate, hookimpl

    assert Candidate.__module__ == "tsrkit.core.types" and callable(hookimpl)
    assert set(tsrkit.__all__) <= set(dir(tsrkit))
    assert tsrkit.datasets.open_datasets.__module__ == "tsrkit.datasets.concat"
    assert not hasattr(tsrkit, "no_such_name")
