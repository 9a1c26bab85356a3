"""The plugin registry: in-process registration, entry-point discovery, failures, filtering."""

import json
import os
import subprocess
import sys

import pytest

import tsrkit
from tsrkit.plugin.hookspecs import hookimpl
from tsrkit.plugin.params import Param, ParamError
from tsrkit.plugin.registry import PluginNotFound, Registry


class Dummy(tsrkit.Detector):
    name = "dummy"
    summary = "returns nothing"
    PARAMS = (Param("k", "int", 1, min=1, max=3),)

    def detect(self, frame):
        return []


class DummyPlugin:
    @hookimpl
    def register_detectors(register):
        register(Dummy)


def test_register_and_unregister_in_process():
    reg = Registry()
    reg.add(DummyPlugin, "dummy-plugin")
    assert [p.name for p in reg.plugins("detector")] == ["dummy"]
    detector = reg.create("detector", "dummy", {"k": "2"})
    assert isinstance(detector, Dummy) and detector.params == {"k": 2}
    with pytest.raises(ParamError, match="detector 'dummy': parameter 'k'"):
        reg.create("detector", "dummy", {"k": 7})
    reg.remove("dummy-plugin")
    with pytest.raises(PluginNotFound, match="no detector called 'dummy'"):
        reg.get("detector", "dummy")


def test_duplicate_names_keep_the_first_and_record_a_failure():
    class Again:
        @hookimpl
        def register_detectors(register):
            register(Dummy)

    reg = Registry()
    reg.add(DummyPlugin, "first")
    reg.add(Again, "second")
    assert [p.name for p in reg.plugins("detector")] == ["dummy"]
    assert any("duplicate detector name 'dummy'" in f.error for f in reg.failures)


def test_a_register_hook_that_raises_does_not_stop_the_others():
    class Broken:
        @hookimpl
        def register_detectors(register):
            raise RuntimeError("boom")

    reg = Registry()
    reg.add(Broken, "broken")
    reg.add(DummyPlugin, "good")
    assert [p.name for p in reg.plugins("detector")] == ["dummy"]
    assert [(f.plugin, f.error) for f in reg.failures] == [
        ("broken", "register: RuntimeError: boom")
    ]


def test_a_misspelled_hook_fails_loudly():
    class Misspelled:
        @hookimpl
        def register_detector(register):  # missing "s"
            register(Dummy)

    reg = Registry()
    reg.add(Misspelled, "typo")
    with pytest.raises(Exception, match="unknown hook 'register_detector'"):
        reg.pm.check_pending()


def test_wrong_kind_is_refused():
    class WrongKind:
        @hookimpl
        def register_classifiers(register):
            register(Dummy)

    reg = Registry()
    reg.add(WrongKind, "wrong")
    assert reg.plugins("classifier") == []
    assert "is not a classifier plugin class" in reg.failures[0].error


def test_entry_points_load_builtins_and_respect_the_filter():
    reg = Registry()
    reg.load_entry_points("format-*")
    assert reg.plugins("format") or reg.failures  # the filter admitted the format entry points
    # Report writers and the core's metrics and verbs load whatever the filter says.
    always = {"format", "metric", "writer"}
    assert {info.kind for info in reg.plugins()} == always
    assert all(f.plugin.startswith("format-") for f in reg.failures)
    everything = Registry()
    everything.load_entry_points(None)
    names = {info.name for info in everything.plugins()} | {f.plugin for f in everything.failures}
    assert {"conspicuity", "gray-tophat", "lab-frst"} <= names
    none = Registry()
    none.load_entry_points("")
    assert {info.kind for info in none.plugins()} == {"metric", "writer"}
    assert none.plugins("detector") == [] and none.failures == []
    verbs = {impl.plugin_name for impl in none.pm.hook.register_commands.get_hookimpls()}
    assert verbs == set()  # the CLI registers the built-in verbs itself


def test_plugins_json_lists_a_failing_entry_point(tmp_path):
    """A plugin whose module cannot import is listed as failed; the rest still load."""
    dist = tmp_path / "broken_plugin-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: broken-plugin\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[tsrkit]\nbroken = module_that_does_not_exist\n")
    env = {"PYTHONPATH": str(tmp_path), "PATH": ""}
    out = subprocess.run(
        [sys.executable, "-m", "tsrkit.cli.main", "plugins", "--json"],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    ).stdout
    listing = json.loads(out)
    failed = [p for p in listing if p["kind"] == "failed" and p["name"] == "broken"]
    assert failed and "module_that_does_not_exist" in failed[0]["error"]
    assert failed[0]["package"] == "broken-plugin"


class Stacked(tsrkit.Detector):
    name = "stacked"
    summary = "the candidates of the detector it is built on"
    PARAMS = (Param("inner", "detector", "dummy k=2", options=(Param("share", "float", 1.0),)),)

    def detect(self, frame):
        return self.params["inner"].plugin.detect(frame)


class OldStyle(tsrkit.Detector):
    name = "old-style"
    params = (Param("k", "int", 1),)  # the schema's former name

    def detect(self, frame):
        return []


class MorePlugins:
    @hookimpl
    def register_detectors(register):
        register(Stacked)
        register(OldStyle)


def test_a_plugin_receives_the_plugin_it_is_built_on_and_old_schemas_fail_clearly():
    reg = Registry()
    reg.add(DummyPlugin, "dummy-plugin")
    reg.add(MorePlugins, "more")
    stacked = reg.create("detector", "stacked", {"inner": "dummy k=3 share=0.5"})
    part = stacked.params["inner"]
    assert isinstance(part.plugin, Dummy) and part.plugin.params == {"k": 3}
    assert part.options == {"share": 0.5} and str(part) == "dummy k=3 share=0.5"
    with pytest.raises(ParamError, match="inner: detector 'dummy': parameter 'k'"):
        reg.create("detector", "stacked", {"inner": "dummy k=9"})
    with pytest.raises(ParamError, match="cannot be built on itself"):
        reg.create("detector", "stacked", {"inner": "stacked"})
    assert "name the tuple 'PARAMS'" in " ".join(f.error for f in reg.failures)


def installed_package(site, name: str, code: str):
    """A distribution ``name`` installed on the folder ``site`` (a ``.dist-info`` folder and
    one module) whose one ``tsrkit`` entry point is its module, holding ``code``."""
    module = name.replace("-", "_")
    (site / f"{module}.py").write_text(code)
    info = site / f"{module}-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(f"[tsrkit]\n{module} = {module}\n")
    return site


def run_with(site, *args: str) -> subprocess.CompletedProcess:
    """``tsrkit ARGS`` in a fresh interpreter that sees the packages installed on ``site``."""
    env = {**os.environ, "PYTHONPATH": str(site)}
    command = [sys.executable, "-m", "tsrkit", *args]
    return subprocess.run(command, capture_output=True, text=True, env=env, timeout=300)


def test_a_plugin_calling_sys_exit_at_import_is_a_failed_plugin(tmp_path):
    site = installed_package(tmp_path, "acme-exits", "import sys\nsys.exit(3)\n")
    helped = run_with(site, "--help")
    assert helped.returncode == 0 and "detect" in helped.stdout, helped.stderr
    listed = run_with(site, "plugins", "--json")
    failed = [p for p in json.loads(listed.stdout) if p["kind"] == "failed"]
    assert failed == [
        {
            "name": "acme_exits",
            "kind": "failed",
            "package": "acme-exits",
            "error": "called sys.exit(3) while loading",
        }
    ]


CLASH = """\
import tsrkit
from tsrkit.plugin.hookspecs import hookimpl


class Mine(tsrkit.Detector):
    name = "gray-tophat"
    summary = "another package's detector of a built-in's name"

    def detect(self, frame):
        return []


@hookimpl
def register_detectors(register):
    register(Mine)
"""


def test_a_plugin_of_a_builtins_name_is_one_warning_and_the_builtin_stays(tmp_path):
    site = installed_package(tmp_path, "acme-clash", CLASH)
    result = run_with(site, "plugins", "--json")
    assert result.returncode == 0, result.stderr
    warning = (
        "warning: duplicate detector name 'gray-tophat': registered by acme-clash and by "
        "tsrkit; tsrkit's is kept, acme-clash's is not used\n"
    )
    assert result.stderr == warning
    plugins = json.loads(result.stdout)
    tophat = [p for p in plugins if p["name"] == "gray-tophat"]
    assert [p["package"] for p in tophat] == ["tsrkit"]
