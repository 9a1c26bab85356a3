"""Runs that meet: two runs writing one output (the second refuses; the first's output stays
whole), and a run killed with ``kill -9`` (its worker processes end with it). These need real
processes, so they run ``python -m tsrkit`` as a user would.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

pytestmark = pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads /proc")


def images(folder: Path, count: int, size: int = 96) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    image = np.full((size, size, 3), 40, np.uint8)
    cv2.circle(image, (size // 2, size // 2), 4, (40, 40, 230), -1)
    for k in range(count):
        cv2.imwrite(str(folder / f"{k:03d}.png"), image)
    return folder


def start(args: list[str], cwd: Path) -> subprocess.Popen:
    env = {**os.environ, "TSRKIT_CACHE_DIR": str(cwd / "cache")}
    return subprocess.Popen(
        [sys.executable, "-m", "tsrkit", *args],
        cwd=cwd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def session(sid: int) -> list[int]:
    """Live (not zombie) processes of session ``sid``."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[3]) == sid and fields[0] != "Z":
            found.append(int(entry.name))
    return found


def wait_for(condition, seconds: float) -> bool:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.2)
    return condition()


def test_a_second_detect_into_the_same_file_refuses(tmp_path):
    first_in, second_in = images(tmp_path / "a", 150, 320), images(tmp_path / "b", 3)
    out = tmp_path / "same.jsonl"
    partial = tmp_path / "same.jsonl.partial"
    first = start(["detect", str(first_in), "-d", "lab-frst", "-o", str(out)], tmp_path)
    try:
        assert wait_for(lambda: partial.exists() and partial.stat().st_size > 0, 180)
        second = start(["detect", str(second_in), "-d", "gray-tophat", "-o", str(out)], tmp_path)
        _, error = second.communicate(timeout=300)
        if first.poll() is not None:
            pytest.skip("the first run ended before the second started (a very slow machine)")
        assert second.returncode == 2, error
        assert "another run" in error and "Traceback" not in error
    finally:
        first.communicate(timeout=900)
    assert first.returncode == 0
    lines = out.read_text().splitlines()
    assert len(lines) == 150 and all("/a/" in line for line in lines)


def test_kill_9_of_a_benchmark_ends_its_workers(tmp_path):
    folder = images(tmp_path / "frames", 200)
    dataset = tmp_path / "annotations.json"
    dataset.write_text(
        "["
        + ", ".join(f'{{"file": "frames/{p.name}", "boxes": []}}' for p in sorted(folder.iterdir()))
        + "]"
    )
    run = start(
        ["benchmark", "--dataset", str(dataset), "-d", "lab-frst", "-w", "2", "-q", "--no-cache"],
        tmp_path,
    )
    try:
        assert wait_for(lambda: len(session(run.pid)) >= 4, 180), "the workers did not start"
        os.kill(run.pid, signal.SIGKILL)
        assert wait_for(lambda: not session(run.pid), 20), session(run.pid)
    finally:
        for pid in session(run.pid):  # only this test's own processes
            os.kill(pid, signal.SIGKILL)
        run.communicate()
