"""A wheel built from the checkout, installed in a fresh venv outside the source tree, finds its
dataset registry and its built-in plugins (no editable install, no repository beside it)."""

import json
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def test_wheel_installs_and_lists_datasets_outside_the_checkout(tmp_path):
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "--quiet",
            "--no-deps",
            "--no-build-isolation",
            "--wheel-dir",
            str(tmp_path / "dist"),
            str(REPO),
        ],
        check=True,
        capture_output=True,
        cwd=tmp_path,
    )
    (wheel,) = (tmp_path / "dist").glob("tsrkit-*.whl")
    env_dir = tmp_path / "venv"
    venv.EnvBuilder(with_pip=False).create(env_dir)
    python = env_dir / "bin" / "python"
    site = Path(
        subprocess.run(
            [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
            check=True,
            capture_output=True,
            text=True,
        ).stdout.strip()
    )
    # The dependencies come from this interpreter's site-packages (a plain path: its .pth
    # files, such as the editable tsrkit, are not processed); tsrkit itself from the wheel.
    (site / "deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "--quiet",
            "--no-deps",
            "--target",
            str(site),
            str(wheel),
        ],
        check=True,
        capture_output=True,
        cwd=tmp_path,
    )
    where = subprocess.run(
        [str(python), "-c", "import tsrkit; print(tsrkit.__file__)"],
        check=True,
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert Path(where.stdout.strip()).is_relative_to(site)
    listed = subprocess.run(
        [str(python), "-m", "tsrkit", "datasets", "list", "--json"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert listed.returncode == 0, listed.stderr
    names = {row["name"] for row in json.loads(listed.stdout)}
    assert {"sample", "roboflow_traffic_light_kr", "udacity_mit_tl_crops"} <= names
    plugins = subprocess.run(
        [str(python), "-m", "tsrkit", "plugins", "--json"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    found = {(p["kind"], p["name"]) for p in json.loads(plugins.stdout)}
    assert {("detector", "conspicuity"), ("writer", "json"), ("metric", "coco-ap")} <= found
