"""``--engine dask`` against a real cluster: a scheduler and two workers as separate processes."""

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

BIN = Path(sys.executable).parent


def start(args, tmp_path, name):
    log = open(tmp_path / f"{name}.log", "wb")  # noqa: SIM115 - closed with the process
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    return subprocess.Popen([str(BIN / "dask"), *args], stdout=log, stderr=log, env=env), log


def wait_for(path: Path, seconds: float = 60) -> dict:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if path.is_file():
            try:
                return json.loads(path.read_text())
            except ValueError:
                pass
        time.sleep(0.2)
    raise AssertionError(f"{path} never appeared")


def workers_of(address: str) -> int:
    from distributed import Client

    with Client(address, timeout="20s") as client:
        return len(client.scheduler_info()["workers"])


@pytest.fixture
def cluster(tmp_path):
    if not (BIN / "dask").is_file():
        pytest.skip("the dask command is not installed beside this Python")
    file = tmp_path / "scheduler.json"
    procs = [
        start(
            [
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--no-dashboard",
                "--scheduler-file",
                str(file),
            ],
            tmp_path,
            "scheduler",
        )
    ]
    try:
        address = wait_for(file)["address"]
        for k in range(2):
            procs.append(
                start(
                    [
                        "worker",
                        address,
                        "--nthreads",
                        "1",
                        "--no-dashboard",
                        "--name",
                        f"w{k}",
                        "--local-directory",
                        str(tmp_path / f"w{k}"),
                    ],
                    tmp_path,
                    f"worker{k}",
                )
            )
        deadline = time.monotonic() + 60
        while workers_of(address) < 2:
            assert time.monotonic() < deadline, "the two workers never joined"
            time.sleep(0.3)
        yield address
    finally:
        for proc, log in reversed(procs):
            proc.terminate()
            try:
                proc.wait(20)
            except subprocess.TimeoutExpired:
                proc.kill()
            log.close()


def benchmark(tmp_path, name, *extra):
    out = tmp_path / name
    subprocess.run(
        [
            str(BIN / "tsrkit"),
            "benchmark",
            "-d",
            "gray-tophat",
            "--no-cache",
            "-q",
            "-o",
            str(out),
            *extra,
        ],
        check=True,
        env={**os.environ, "OMP_NUM_THREADS": "1"},
    )
    report = json.loads((out / "report.json").read_text())
    return report.pop("timing"), report


def test_cluster_of_separate_processes_gives_the_local_report(cluster, tmp_path):
    _, local = benchmark(tmp_path, "local", "-w", "1")
    timing, remote = benchmark(tmp_path, "dask", "--engine", "dask", "--scheduler", cluster)
    assert timing["engine"] == "dask"
    assert remote == local
    assert local["frames"] == 48 and local["skipped"] == []
