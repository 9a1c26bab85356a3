"""The README's quick tour, run as written: every command line of its two blocks, then its
Python script, in a fresh folder, with the virtual environment's ``tsrkit`` first on ``PATH``
(as ``source .venv/bin/activate`` puts it).

The real-dataset block runs against a trimmed copy of the shared datasets (a few frames of each
split, linked, with annotation files and checksum manifests to match), as the README says, so
that the tour takes a couple of minutes in CI; the synthetic block runs at the sizes it names.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import REPO

README = REPO / "README.md"
#: Frames kept per split (normalised sets) or per split and label (crop sets).
KEEP = 3


def tour_blocks() -> tuple[list[str], list[str], str]:
    """The command lines of the tour's two ``bash`` blocks (continuations joined) and the
    ``python`` block after them."""
    text = README.read_text(encoding="utf-8")
    tour = text[text.index("## Quick tour") : text.index("## Methods")]
    blocks = re.findall(r"```bash\n(.*?)```", tour, re.S)
    lines = [
        [line for line in block.replace("\\\n", " ").splitlines() if line.strip()]
        for block in blocks[:2]
    ]
    script = re.findall(r"```python\n(.*?)```", tour, re.S)[0]
    return lines[0], lines[1], script


def trimmed_datasets(shared: Path, target: Path) -> Path:
    """A copy of the shared datasets the tour uses, ``KEEP`` frames of each split (and label,
    for crops): images linked, annotation files and ``MANIFEST.sha256`` rewritten."""
    for name in ("roboflow_traffic_light_kr", "roboflow_cinta_v2_id", "dtld_fridtjofs"):
        records = json.loads((shared / name / "annotations.json").read_text(encoding="utf-8"))
        kept = _first_of_each(records, lambda r: r.get("split"))
        _link(shared / name, target / name, [r["file"] for r in kept])
        _write(target / name / "annotations.json", json.dumps(kept))
    name = "udacity_mit_tl_crops"
    with open(shared / name / "labels.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    kept = _first_of_each(rows, lambda r: (r["split"], r["label"]))
    _link(shared / name, target / name, [r["file"] for r in kept])
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(kept)
    _write(target / name / "labels.csv", out.getvalue())
    for folder in target.iterdir():
        _manifest(folder)
    (target / "README.md").write_text("trimmed copy of the shared datasets for the tour test\n")
    return target


def _first_of_each(items: list, key) -> list:
    counts: dict = {}
    kept = []
    for item in items:
        group = key(item)
        if counts.get(group, 0) < KEEP:
            counts[group] = counts.get(group, 0) + 1
            kept.append(item)
    return kept


def _link(source: Path, target: Path, files: list[str]) -> None:
    for name in files:
        path = target / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if not path.exists():
            os.symlink(source / name, path)


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")


def _manifest(folder: Path) -> None:
    lines = [
        f"{hashlib.sha256(path.read_bytes()).hexdigest()}  ./{path.relative_to(folder)}"
        for path in sorted(folder.rglob("*"))
        if path.is_file() and path.name != "MANIFEST.sha256"
    ]
    (folder / "MANIFEST.sha256").write_text("\n".join(lines) + "\n")


@pytest.fixture(scope="module")
def tour(tmp_path_factory, shared_datasets):
    """The folder the tour ran in, and each command's result."""
    synthetic, real, script = tour_blocks()
    folder = tmp_path_factory.mktemp("tour")
    data = trimmed_datasets(shared_datasets, tmp_path_factory.mktemp("data"))
    env = {
        **os.environ,
        "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}",
        "TSRKIT_DATA_DIR": str(data),
        "TSRKIT_CACHE_DIR": str(folder / ".cache"),
    }
    results = []
    for line in [*synthetic, *real]:
        done = subprocess.run(
            ["bash", "-e", "-o", "pipefail", "-c", line],
            cwd=folder,
            env=env,
            capture_output=True,
            text=True,
            timeout=900,
        )
        results.append((line, done))
    (folder / "tour.py").write_text(script, encoding="utf-8")
    done = subprocess.run(
        [sys.executable, "tour.py"], cwd=folder, env=env, capture_output=True, text=True
    )
    results.append(("python tour.py", done))
    return folder, results


def test_the_tour_has_both_blocks_and_the_script():
    synthetic, real, script = tour_blocks()
    assert all(line.startswith("tsrkit ") for line in synthetic + real)
    assert len(synthetic) >= 10 and len(real) >= 10
    assert 'if __name__ == "__main__":' in script


def test_every_tour_command_succeeds(tour):
    _, results = tour
    failed = [
        f"{line}\n  exit {done.returncode}: {(done.stderr or done.stdout).strip()[-600:]}"
        for line, done in results
        if done.returncode != 0
    ]
    assert not failed, "\n".join(failed)
    assert all("Traceback" not in done.stderr for _, done in results)


def test_the_tour_makes_what_it_says(tour):
    folder, _ = tour
    for made in (
        "run.yaml",
        "drive.mp4",
        "drive.jsonl",
        "dets.jsonl",
        "city/gps.csv",
        "city/map.osm",
        "runs/drive/traversals.jsonl",
        "models/synth.npz",
        "tsrkit-out/report.json",
        "runs/kr/report.json",
        "runs/verifier/compare.json",
        "runs/cinta/compare.json",
        "kr.coco.json",
        "models/ab.npz",
        "models/v.npz",
    ):
        assert (folder / made).is_file(), made
    assert any((folder / "overlays").iterdir())


def test_the_tracker_line_yields_tracked_records(tour):
    folder, _ = tour
    records = [json.loads(line) for line in (folder / "tracked.jsonl").read_text().splitlines()]
    origins = {d["origin"] for r in records for d in r["detections"]}
    assert origins == {"detected", "tracked"}, origins


def test_the_video_range_line_decodes_the_frames_it_names(tour):
    _, results = tour
    done = next(d for line, d in results if "--every 2 --start 2 --end 10" in line)
    frames = [json.loads(line)["frame"] for line in done.stdout.splitlines()]
    assert frames == [2, 4, 6, 8]
