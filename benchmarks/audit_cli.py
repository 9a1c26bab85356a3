"""A stranger's hostile audit of the command line: run each case of
``benchmarks/audit_cli_cases.py`` in a fresh folder, through ``python -m tsrkit`` in a new
process (so that hangs, signals and concurrent runs are real), and classify what happened.

Verdicts: ``fine``; ``traceback`` (an uncaught exception or a signal); ``hang`` (no end
within the case's time limit, or workers left running); ``silent`` (a wrong answer with exit
status 0 and no word); ``lost`` (an input or a finished output overwritten or mixed);
``refused`` (a valid input refused); ``unclear`` (a refusal that is not one clear line with the
right exit code and message).

Run from the repository root::

    python benchmarks/audit_cli.py --out benchmarks/out/audit_cli/after.json
    python benchmarks/audit_cli.py --base /tmp/base --out benchmarks/out/audit_cli/before.json
    python benchmarks/audit_cli.py --summarize benchmarks/out/audit_cli/before.json \\
        benchmarks/out/audit_cli/after.json

``--base DIR`` runs another commit's code: DIR holds ``tsrkit`` and ``tsrkit_plugins`` (links
to a checkout's ``tsrkit/`` and ``plugins/``), put first on ``PYTHONPATH``. The fixtures (a
64x64 image, a 4-frame synthetic dataset and its video, a rendered drive) are made once under
``--root``. Every case runs with ``OMP_NUM_THREADS=1``; ``-j`` cases run at a time.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(os.environ.get("AUDIT_ROOT", "benchmarks/out/audit_cli")).resolve()
FX = ROOT / "fx"
PY = sys.executable
BASE: Path | None = None


@dataclass
class Result:
    code: int | None
    out: str
    seconds: float


@dataclass
class Case:
    id: str
    area: str
    argv: list[str] | None
    expect: tuple[int, str] | None  # the right behaviour: exit code and a message regex
    setup: Callable[[Path], object] | None = None
    timeout: float = 90
    wrong: str = ""  # verdict when the outcome differs and nothing else applies
    check: Callable[[Path, Result], tuple[str, str] | None] | None = None
    run: Callable[[Path], tuple[str, str]] | None = None  # a custom case
    env: dict = field(default_factory=dict)
    note: str = ""


CASES: list[Case] = []


def case(id, area, argv, expect, **kw) -> None:
    assert id not in {c.id for c in CASES}, id
    CASES.append(Case(id, area, argv, expect, **kw))


def command() -> list[str]:
    return [PY, "-m", "tsrkit"]


def environment(tmp: Path, extra: dict) -> dict:
    env = dict(os.environ)
    env.update(
        TSRKIT_CACHE_DIR=str(tmp / ".cache"),
        OMP_NUM_THREADS="1",
        OPENBLAS_NUM_THREADS="1",
        COLUMNS="200",
    )
    if BASE is not None:
        env["PYTHONPATH"] = str(BASE)
    env.update(extra)
    return env


def start(tmp: Path, argv: list[str], env: dict | None = None, **kw) -> subprocess.Popen:
    return subprocess.Popen(
        [*command(), *argv],
        cwd=tmp,
        env=environment(tmp, env or {}),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        stdin=subprocess.DEVNULL,
        start_new_session=True,
        text=True,
        errors="replace",
        **kw,
    )


def finish(proc: subprocess.Popen, timeout: float) -> Result:
    began = time.perf_counter()
    try:
        out, _ = proc.communicate(timeout=timeout)
        code = proc.returncode
    except subprocess.TimeoutExpired:
        kill_group(proc)
        out, _ = proc.communicate()
        code = None
    return Result(code, out or "", time.perf_counter() - began)


def kill_group(proc: subprocess.Popen) -> None:
    """End the process group this script started for ``proc`` (its own session)."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGKILL)


def invoke(tmp: Path, argv: list[str], timeout: float = 40, env: dict | None = None) -> Result:
    return finish(start(tmp, argv, env), timeout)


def fmt(argv: list[str], tmp: Path) -> list[str]:
    return [a.replace("{tmp}", str(tmp)).replace("{fx}", str(FX)) for a in argv]


def tail(text: str) -> str:
    lines = [x.strip() for x in text.strip().splitlines() if x.strip()]
    return " | ".join(lines[-2:])[:200]


def verdict(c: Case, tmp: Path, r: Result) -> tuple[str, str]:
    if r.code is None:
        return "hang", f"no end within {c.timeout:.0f} s"
    if "Traceback (most recent call last)" in r.out:
        last = [line for line in r.out.strip().splitlines() if line.strip()][-1]
        return "traceback", last[:160]
    if r.code not in (0, 1, 2):
        return "traceback", f"exit {r.code} (killed by a signal?)"
    if c.check is not None:
        checked = c.check(tmp, r)
        if checked is not None:
            return checked
    if c.expect is None:
        return "fine", ""
    code, pattern = c.expect
    if r.code == code and re.search(pattern, r.out.replace(str(tmp), "TMP"), re.I | re.S):
        lines = [x for x in r.out.splitlines() if x.strip()]
        if code == 2 and len(lines) > 3:
            return "unclear", f"{len(lines)} lines of error"
        if code == 2 and len(r.out) > 2000:
            return "unclear", f"{len(r.out)} characters of error"
        return "fine", ""
    if c.wrong:
        return c.wrong, f"exit {r.code}: {tail(r.out)}"
    if code != 0 and r.code == 0:
        return "silent", f"exit 0: {tail(r.out)}"
    if code == 0 and r.code != 0:
        return "refused", f"exit {r.code}: {tail(r.out)}"
    return "unclear", f"exit {r.code} (want {code} /{pattern}/): {tail(r.out)}"


def run_case(c: Case) -> dict:
    tmp = ROOT / "run" / c.id
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    out, seconds = "", 0.0
    try:
        if c.setup is not None:
            c.setup(tmp)
        if c.run is not None:
            kind, note = c.run(tmp)
        else:
            r = invoke(tmp, fmt(c.argv or [], tmp), c.timeout, c.env)
            kind, note = verdict(c, tmp, r)
            seconds, out = r.seconds, r.out
    except Exception as exc:  # a bug of this script must not end the audit
        kind, note = "harness-error", f"{type(exc).__name__}: {exc}"
    return {
        "id": c.id,
        "area": c.area,
        "verdict": kind,
        "note": note,
        "seconds": round(seconds, 1),
        "output": out[-1500:],
    }


def make_fixtures() -> None:
    """The shared inputs of the cases, made once with the code under test's own tools (the
    current tree's, whatever ``--base`` says)."""
    if (FX / "drive" / "truth.jsonl").is_file():
        return
    import cv2
    import numpy as np

    from tsrkit.synth import generate
    from tsrkit.synth.drive import DriveOptions, render_drive
    from tsrkit.synth.video import write_video

    shutil.rmtree(FX, ignore_errors=True)
    (FX / "img").mkdir(parents=True)
    image = np.full((64, 64, 3), 40, np.uint8)
    cv2.circle(image, (32, 32), 4, (40, 40, 230), -1)
    cv2.imwrite(str(FX / "img" / "good.png"), image)
    cv2.imwrite(str(FX / "img" / "good.jpg"), image)
    dataset = generate(FX / "ds", 4, 0, 64, 64)
    write_video(dataset, FX / "ds.mp4")
    subprocess.run(
        [*command(), "datasets", "convert", str(FX / "ds" / "annotations.json"), "--to", "coco"]
        + ["--out", str(FX / "ds" / "coco.json"), "-q"],
        check=True,
        capture_output=True,
    )
    options = DriveOptions(width=160, height=120, fps=5, route=("left",), lead_m=40, tail_m=15)
    render_drive(FX / "drive", options, seed=3)


def summarize(files: list[str]) -> None:
    """Print each result file's counts by verdict, and the cases whose verdict changed."""
    runs = {name: {r["id"]: r for r in json.loads(Path(name).read_text())} for name in files}
    kinds = sorted({r["verdict"] for rows in runs.values() for r in rows.values()})
    print("| results | cases | " + " | ".join(kinds) + " |")
    print("|---|---|" + "---|" * len(kinds))
    for name, rows in runs.items():
        counts = Counter(r["verdict"] for r in rows.values())
        print(f"| {name} | {len(rows)} | " + " | ".join(str(counts[k]) for k in kinds) + " |")
    if len(runs) == 2:
        (_, before), (b, after) = runs.items()
        print(f"\nnot fine in {b}:")
        for key, row in sorted(after.items()):
            if row["verdict"] != "fine":
                old = before.get(key, {}).get("verdict", "-")
                print(f"- {key}: {old} -> {row['verdict']}: {row['note']}")


def main() -> None:
    global BASE
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", type=Path, help="folder with tsrkit/ and tsrkit_plugins/")
    parser.add_argument("-k", default="", help="comma-separated substrings of case ids")
    parser.add_argument("--out", help="results (JSON)")
    parser.add_argument("-j", "--jobs", type=int, default=2)
    parser.add_argument("--summarize", nargs="+", metavar="RESULTS")
    args = parser.parse_args()
    if args.summarize:
        summarize(args.summarize)
        return
    BASE = args.base.resolve() if args.base else None
    make_fixtures()
    import audit_cli_cases
    from audit_cli_cases import REVIEWED

    del audit_cli_cases
    chosen = [c for c in CASES if any(k in c.id for k in args.k.split(","))]
    results = []
    from concurrent.futures import ThreadPoolExecutor, as_completed

    with ThreadPoolExecutor(args.jobs) as pool:
        for future in as_completed([pool.submit(run_case, c) for c in chosen]):
            row = future.result()
            if BASE is not None and row["id"] in REVIEWED:
                row["verdict"], row["note"] = REVIEWED[row["id"]]
            results.append(row)
            print(f"{row['verdict']:10} {row['id']:40} {row['note']}", flush=True)
    order = [c.id for c in chosen]
    results.sort(key=lambda r: order.index(r["id"]))
    print(dict(Counter(r["verdict"] for r in results)))
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).parent))
    sys.modules["audit_cli"] = sys.modules["__main__"]
    main()
