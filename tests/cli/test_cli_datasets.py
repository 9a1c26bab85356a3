"""``tsrkit datasets list | info | verify | convert``."""

from __future__ import annotations

import json
import shutil

from click.testing import CliRunner

from tsrkit.cli.main import cli


def _run(*args):
    return CliRunner().invoke(cli, ["datasets", *args])


def test_list_json_names_every_entry(shared_datasets):
    result = _run("list", "--json")
    assert result.exit_code == 0, result.output
    rows = {row["name"]: row for row in json.loads(result.output)}
    assert rows["roboflow_cinta_v2_id"]["present"] == "yes"
    assert rows["sample"]["present"] == "generated"
    assert rows["gtsrb_test_35px_subset"]["format"] == "gtsrb"


def test_info_counts_states(shared_datasets):
    result = _run("info", "roboflow_traffic_light_kr", "--json")
    assert result.exit_code == 0, result.output
    info = json.loads(result.output)
    assert info["samples"] == 38 and info["annotations"] == 82
    assert info["states"] == {"green": 49, "red": 27, "yellow": 6}
    assert info["labels"]["left"] == 21


def test_verify_real_set_passes(shared_datasets):
    result = _run("verify", "roboflow_traffic_light_kr")
    assert result.exit_code == 0, result.output
    assert "80 files checked, 0 missing, 0 altered" in result.output


def test_verify_reports_missing_and_altered(shared_datasets, tmp_path, monkeypatch):
    copy = tmp_path / "kr"
    shutil.copytree(shared_datasets / "roboflow_traffic_light_kr", copy)
    copy.chmod(0o755)
    (copy / "data.yaml").chmod(0o644)
    (copy / "data.yaml").write_text("names: [changed]\n")
    (copy / "README.dataset.txt").chmod(0o644)
    (copy / "README.dataset.txt").unlink()
    registry = tmp_path / "datasets.yaml"
    registry.write_text(f"""datasets:
  kr:
    format: normalized
    root: {copy}
    path: annotations.json
    task: detection
    box: housing
    licence: CC BY 4.0
    citation: x
    manifest: MANIFEST.sha256
""")
    monkeypatch.setenv("TSRKIT_DATASETS_YAML", str(registry))
    result = _run("verify", "kr")
    assert result.exit_code == 1
    assert "missing: README.dataset.txt" in result.output
    assert "altered: data.yaml" in result.output


def test_convert_and_errors(shared_datasets, tmp_path):
    out = tmp_path / "coco.json"
    result = _run(
        "convert",
        str(shared_datasets / "roboflow_cinta_v2_id"),
        "--format",
        "yolo",
        "--to",
        "coco",
        "--out",
        str(out),
    )
    assert result.exit_code == 0, result.output
    assert "300 images, 403 boxes" in result.output
    coco = json.loads(out.read_text())
    assert len(coco["images"]) == 300 and len(coco["annotations"]) == 403
    result = _run(
        "convert", str(shared_datasets / "roboflow_cinta_v2_id"), "--to", "coco", "--out", str(out)
    )
    assert result.exit_code == 2 and "--format" in result.output
    assert "Traceback" not in result.output
    result = _run("convert", "udacity_mit_tl_crops", "--to", "lisa", "--out", str(out))
    assert result.exit_code == 2 and "no writer" in result.output
