"""The docstring examples of the built-in plugins run (the core's run through pytest's
``--doctest-modules``; ``plugins/`` installs as ``tsrkit_plugins``, so it is walked here)."""

import doctest
import importlib
import pkgutil

import pytest

import tsrkit_plugins

MODULES = sorted(m.name for m in pkgutil.walk_packages(tsrkit_plugins.__path__, "tsrkit_plugins."))


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed"
