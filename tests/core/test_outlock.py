"""Runs that cannot collide: one live run per output folder; a killed run's lock is taken over."""

import subprocess
import sys

import pytest
from benchmark_fakes import OracleDetector, hand_dataset, make

from tsrkit.reporting.benchmarking import benchmark
from tsrkit.runner.outlock import LOCK, OutputBusy, locked


def test_a_second_live_run_into_the_same_out_refuses(tmp_path):
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        tmp_path.mkdir(exist_ok=True)
        (tmp_path / LOCK).write_text(str(sleeper.pid))
        with pytest.raises(OutputBusy, match=f"process {sleeper.pid}"):
            benchmark(hand_dataset(2), make(OracleDetector), cache=False, out=tmp_path)
        assert not (tmp_path / "report.json").exists()
    finally:
        sleeper.kill()
        sleeper.wait()


def test_a_killed_runs_lock_and_temporary_files_are_taken_over(tmp_path):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    (tmp_path / LOCK).write_text(str(dead.pid))
    (tmp_path / ".report.json.abc.tmp").write_text("half")
    report = benchmark(hand_dataset(2), make(OracleDetector), cache=False, out=tmp_path)
    assert report["frames"] == 2
    assert not (tmp_path / LOCK).exists() and not (tmp_path / ".report.json.abc.tmp").exists()


def test_the_lock_is_released_when_the_run_fails(tmp_path):
    with pytest.raises(RuntimeError), locked(tmp_path):
        raise RuntimeError("boom")
    assert not (tmp_path / LOCK).exists()
