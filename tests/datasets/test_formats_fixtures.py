"""Readers for formats absent from shared/datasets, on small hand-written files."""

from __future__ import annotations

import json

import pytest

from tsrkit.datasets import DatasetError, open_dataset

BOSCH_YAML = """\
- boxes:
  - {label: RedLeft, occluded: false, x_max: 30.0, x_min: 20.0, y_max: 40.0, y_min: 10.0}
  - {label: Green, occluded: true, x_max: 100.0, x_min: 110.0, y_max: 60.0, y_min: 50.0}
  - {label: off, occluded: false, x_max: 1290.0, x_min: 1270.0, y_max: 30.0, y_min: -5.0}
  path: ./rgb/train/a/1.png
- boxes: []
  path: ./rgb/train/a/2.png
"""


def test_bosch_yaml_maps_labels_and_repairs_boxes(tmp_path):
    file = tmp_path / "train.yaml"
    file.write_text(BOSCH_YAML)
    ds = open_dataset(file)
    assert ds.format == "bosch" and len(ds) == 2
    anns = ds.samples[0].annotations
    assert [(a.attributes["label"], a.state) for a in anns] == [
        ("RedLeft", "red"),
        ("Green", "green"),
        ("off", "off"),
    ]
    assert anns[1].bbox == (100, 50, 110, 60)
    assert anns[2].bbox == (1270, 0, 1280, 30)
    assert ds.info["repaired"] == 2 and ds.info["dropped"] == 0
    assert ds.samples[0].source == str(tmp_path / "rgb/train/a/1.png")


def test_bosch_json_reads_like_yaml_and_drops_empty_boxes(tmp_path):
    entries = [
        {
            "path": "x.png",
            "boxes": [
                {"label": "Yellow", "x_min": 1, "y_min": 2, "x_max": 5, "y_max": 9},
                {"label": "Red", "x_min": 1300, "y_min": 2, "x_max": 1400, "y_max": 9},
            ],
        }
    ]
    file = tmp_path / "test.json"
    file.write_text(json.dumps(entries))
    ds = open_dataset(file, format="bosch")
    assert [a.state for a in ds.samples[0].annotations] == ["yellow"]
    assert ds.info["dropped"] == 1 and ds.info["repaired"] == 1


def test_bosch_unknown_label_names_entry(tmp_path):
    file = tmp_path / "bad.yaml"
    file.write_text(
        "- boxes:\n  - {label: Purple, x_max: 2, x_min: 1, y_max: 2, y_min: 1}\n  path: a.png\n"
    )
    with pytest.raises(DatasetError, match=r"bad.yaml: entry 0 box 0: unknown label 'Purple'"):
        open_dataset(file, format="bosch")


LISA = """\
Filename;Annotation tag;Upper left corner X;Upper left corner Y;Lower right corner X;\
Lower right corner Y;Origin file;Origin frame number;Origin track;Origin track frame number
dayTest/daySequence1--00000.jpg;stop;700;300;720;340;seq.mp4;0;seq.mp4;0
dayTest/daySequence1--00000.jpg;goLeft;800;310;815;350;seq.mp4;0;seq.mp4;0
dayTest/daySequence1--00001.jpg;warningLeft;701;301;721;341;seq.mp4;1;seq.mp4;1
"""


def test_lisa_box_csv_groups_rows_by_frame(tmp_path):
    folder = tmp_path / "daySequence1"
    folder.mkdir()
    (folder / "frameAnnotationsBOX.csv").write_text(LISA)
    ds = open_dataset(folder)
    assert ds.format == "lisa" and ds.info["box"] == "housing" and len(ds) == 2
    assert [(a.attributes["label"], a.state) for a in ds.samples[0].annotations] == [
        ("stop", "red"),
        ("goLeft", "green"),
    ]
    assert ds.samples[1].annotations[0].state == "yellow"
    images = tmp_path / "frames"
    ds = open_dataset(folder / "frameAnnotationsBOX.csv", images=images)
    assert ds.samples[0].source == str(images / "daySequence1--00000.jpg")


def test_lisa_bulb_kind_and_malformed_line(tmp_path):
    (tmp_path / "frameAnnotationsBULB.csv").write_text(LISA)
    ds = open_dataset(tmp_path / "frameAnnotationsBULB.csv")
    assert ds.info["box"] == "lens"
    bad = tmp_path / "frameAnnotationsBOX.csv"
    bad.write_text(LISA + "dayTest/x.jpg;stop;700;300\n")
    with pytest.raises(DatasetError, match=r"frameAnnotationsBOX.csv: line 5: empty or missing"):
        open_dataset(bad)


def _dtld(labels):
    return {"images": [{"image_path": "Berlin/a.tiff", "time_stamp": 12.5, "labels": labels}]}


def test_dtld_states_and_attributes(tmp_path):
    labels = [
        {
            "x": 10,
            "y": 20,
            "w": 5,
            "h": 12,
            "unique_id": 7,
            "track_id": "t1",
            "attributes": {"state": "red_yellow", "pictogram": "circle", "direction": "front"},
        },
        {"x": 40, "y": 20, "w": 5, "h": 12, "attributes": {"state": "off"}},
    ]
    file = tmp_path / "DTLD_test.json"
    file.write_text(json.dumps(_dtld(labels)))
    ds = open_dataset(file)
    first, second = ds.samples[0].annotations
    assert first.bbox == (10, 20, 15, 32) and first.state == "red_yellow"
    assert first.attributes["label"] == "red_yellow" and first.attributes["pictogram"] == "circle"
    assert first.attributes["unique_id"] == 7 and second.state == "off"
    assert ds.samples[0].metadata["timestamp"] == 12.5
    assert ds.samples[0].source == str(tmp_path / "Berlin/a.tiff")


def test_dtld_malformed_label_names_entry(tmp_path):
    file = tmp_path / "d.json"
    file.write_text(json.dumps(_dtld([{"x": 1, "y": 2, "w": 3, "attributes": {"state": "red"}}])))
    with pytest.raises(DatasetError, match=r"d.json: images\[0\].labels\[0\]: missing 'h'"):
        open_dataset(file, format="dtld")


LARA = """\
# Timestamp / frameindex x1 y1 x2 y2 id 'type' 'subtype'
# header comment
93.8 / 6695 404 182 420 219 4 'Traffic Light' 'go'
93.8 / 6695 500 180 516 217 5 'Traffic Light' 'ambiguous'
93.84 / 6696 405 182 421 219 4 'Traffic Light' 'stop'
"""


def test_lara_groups_frames(tmp_path):
    file = tmp_path / "Lara_UrbanSeq1_GroundTruth_GT.txt"
    file.write_text(LARA)
    ds = open_dataset(file)
    assert ds.format == "lara" and len(ds) == 2
    first = ds.samples[0]
    assert first.source == str(tmp_path / "Lara3D_UrbanSeq1_JPG/frame_006695.jpg")
    assert [a.state for a in first.annotations] == ["green", "unknown"]
    assert first.annotations[0].bbox == (404, 182, 420, 219)
    assert first.metadata == {"timestamp": 93.8, "frame": 6695}
    assert ds.samples[1].annotations[0].state == "red"


def test_lara_malformed_line(tmp_path):
    file = tmp_path / "gt.txt"
    file.write_text(LARA + "94.0 / 6697 405 182 'Traffic Light' 'stop'\n")
    with pytest.raises(DatasetError, match=r"gt.txt: line 6: expected .*10 fields"):
        open_dataset(file, format="lara")


VOC = """<annotation><folder>JPEGImages</folder><filename>{name}</filename>
<size><width>640</width><height>480</height><depth>3</depth></size>
<object><name>stop</name><difficult>1</difficult>
<bndbox><xmin>10</xmin><ymin>20</ymin><xmax>30</xmax><ymax>60</ymax></bndbox></object>
</annotation>"""


def test_voc_root_with_image_sets(tmp_path):
    (tmp_path / "Annotations").mkdir()
    (tmp_path / "JPEGImages").mkdir()
    (tmp_path / "JPEGImages/a.jpg").write_bytes(b"")
    (tmp_path / "Annotations/a.xml").write_text(VOC.format(name="a.jpg"))
    (tmp_path / "ImageSets/Main").mkdir(parents=True)
    (tmp_path / "ImageSets/Main/val.txt").write_text("a\n")
    ds = open_dataset(tmp_path)
    sample = ds.samples[0]
    assert ds.format == "voc" and sample.split == "valid"
    assert sample.source == str(tmp_path / "JPEGImages/a.jpg")
    assert (sample.width, sample.height) == (640, 480)
    ann = sample.annotations[0]
    assert (ann.bbox, ann.state, ann.attributes["difficult"]) == ((10, 20, 30, 60), "red", 1)


def test_voc_malformed_xml_names_line(tmp_path):
    file = tmp_path / "a.xml"
    file.write_text(VOC.format(name="a.jpg").replace("</ymax>", ""))
    with pytest.raises(DatasetError, match=r"a.xml: line 4 column \d+: not well-formed XML"):
        open_dataset(file, format="voc")


def test_coco_unknown_category_names_entry(tmp_path):
    file = tmp_path / "c.json"
    file.write_text(
        json.dumps(
            {
                "images": [{"id": 1, "file_name": "a.jpg"}],
                "annotations": [{"image_id": 1, "category_id": 9, "bbox": [1, 2, 3, 4]}],
                "categories": [{"id": 1, "name": "red"}],
            }
        )
    )
    with pytest.raises(DatasetError, match=r"c.json: annotations\[0\]: unknown category_id 9"):
        open_dataset(file)


def test_normalized_bad_json_names_line(tmp_path):
    file = tmp_path / "annotations.json"
    file.write_text('[\n{"file": "a.jpg", "boxes": [}\n]')
    with pytest.raises(DatasetError, match=r"annotations.json: line 2 column \d+: not valid JSON"):
        open_dataset(file, format="normalized")


def test_yolo_bad_label_line(tmp_path):
    (tmp_path / "data.yaml").write_text("names: [red, green]\nval: valid/images\n")
    (tmp_path / "valid/images").mkdir(parents=True)
    (tmp_path / "valid/labels").mkdir()
    import cv2
    import numpy as np

    cv2.imwrite(str(tmp_path / "valid/images/a.png"), np.zeros((10, 20, 3), np.uint8))
    (tmp_path / "valid/labels/a.txt").write_text("0 0.5 0.5 0.2 0.2\n1 0.1 0.2 0.3\n")
    with pytest.raises(DatasetError, match=r"a.txt: line 2: expected 4 box values"):
        open_dataset(tmp_path)
    (tmp_path / "valid/labels/a.txt").write_text("0 0.5 0.5 0.2 0.2\n1 0.1 0.2 0.3 0.2 0.3 0.6\n")
    ds = open_dataset(tmp_path)
    boxes = [a.bbox for a in ds.samples[0].annotations]
    assert boxes[0] == pytest.approx((8, 4, 12, 6))
    assert boxes[1] == pytest.approx((2, 2, 6, 6))


def test_gtsrb_bad_class_id(tmp_path):
    file = tmp_path / "GT-00001.csv"
    file.write_text(
        "Filename;Width;Height;Roi.X1;Roi.Y1;Roi.X2;Roi.Y2;ClassId\n"
        "a.ppm;30;30;5;5;25;25;1\nb.ppm;30;30;5;5;25;25;x\n"
    )
    with pytest.raises(DatasetError, match=r"GT-00001.csv: line 3: class id must be"):
        open_dataset(file)


def test_crops_folder_labels(tmp_path):
    import cv2
    import numpy as np

    for split, label in (("train", "red"), ("test", "green")):
        (tmp_path / split / label).mkdir(parents=True)
        cv2.imwrite(str(tmp_path / split / label / "x.png"), np.zeros((7, 5, 3), np.uint8))
    ds = open_dataset(tmp_path)
    assert ds.format == "crops"
    assert sorted((s.split, s.annotations[0].state, s.annotations[0].bbox) for s in ds) == [
        ("test", "green", (0, 0, 5, 7)),
        ("train", "red", (0, 0, 5, 7)),
    ]
