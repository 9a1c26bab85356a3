"""A third-party plugin, installed by pip like a stranger's package, is found and runs."""
import json
import os
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "tsrkit-brightest-blobs"


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """pip-install the example into its own folder; return an environment that sees it."""
    target = tmp_path_factory.mktemp("site")
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps",
                    "--no-build-isolation", "--no-index", "--target", str(target),
                    str(EXAMPLE)], check=True, capture_output=True)
    env = dict(os.environ, PYTHONPATH=str(target))
    env.pop("TSRKIT_LOAD_PLUGINS", None)
    return env


def tsrkit(env, *args):
    return subprocess.run([sys.executable, "-m", "tsrkit", *args], env=env, capture_output=True,
                          text=True)


def test_installed_plugin_is_listed(installed):
    done = tsrkit(installed, "plugins", "--json")
    assert done.returncode == 0, done.stderr
    (entry,) = [p for p in json.loads(done.stdout) if p["name"] == "brightest-blobs"]
    assert entry == {**entry, "kind": "detector", "package": "tsrkit-brightest-blobs",
                     "version": "0.1.0"}


def test_installed_plugin_detects(installed, tmp_path):
    image = np.full((50, 80, 3), 20, np.uint8)
    cv2.circle(image, (60, 12), 4, (255, 255, 255), -1)
    cv2.imwrite(str(tmp_path / "lamp.png"), image)
    done = tsrkit(installed, "detect", str(tmp_path / "lamp.png"), "--detector",
                  "brightest-blobs", "--param", "top=1")
    assert done.returncode == 0, done.stderr
    (det,) = json.loads(done.stdout)["detections"]
    assert abs(det["x"] - 60) < 1 and abs(det["y"] - 12) < 1


def test_load_filter_hides_it(installed):
    env = dict(installed, TSRKIT_LOAD_PLUGINS="format-*")
    done = tsrkit(env, "plugins", "--json")
    assert all(p["name"] != "brightest-blobs" for p in json.loads(done.stdout))
