"""The plugin registry: in-process registration, entry-point discovery, failures, filtering."""

import json
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
