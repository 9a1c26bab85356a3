"""German Traffic Sign Recognition Benchmark CSV: one sign per image with its ROI and class.

Reads the original semicolon files (``Filename;Width;Height;Roi.X1;Roi.Y1;Roi.X2;Roi.Y2;
ClassId``, e.g. ``GT-final_test.csv`` or the per-class ``GT-000NN.csv``; ROI in the original
image's pixels, images beside the CSV) and the comma ``labels.csv`` of
``shared/datasets/gtsrb_test_35px_subset`` (``file,class_id,class_name_de,...,roi_*_35px``;
the ROI used is the one in the stored 35x35 images, whose size it records). A folder is read
through its ``labels.csv`` when it has one, else through every ``GT-*.csv`` below it.

Signs are not signal states: ``Annotation.state`` holds the class NAME (from
``GTSRB_Class_Names.csv`` beside the file when present, else ``class_name_de``, else the id as
text) and ``attributes["class_id"]`` the integer class id.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

from tsrkit.api import Dataset, DatasetError, DatasetFormat, Sample, hookimpl, read_text
from tsrkit_plugins.formats.common import annotation, checked_box, resolve_image

GT_COLUMNS = ("Filename", "Width", "Height", "Roi.X1", "Roi.Y1", "Roi.X2", "Roi.Y2", "ClassId")
SUBSET_COLUMNS = ("file", "class_id", "roi_x1_35px", "roi_y1_35px", "roi_x2_35px", "roi_y2_35px")
SUBSET_FILE = "labels.csv"
NAMES_FILE = "GTSRB_Class_Names.csv"


def _header(path: Path) -> str:
    with open(path, encoding="utf-8", errors="replace") as fh:
        return fh.readline().strip()


def _is_gt(path: Path) -> bool:
    return path.is_file() and _header(path).split(";")[: len(GT_COLUMNS)] == list(GT_COLUMNS)


def _is_subset(path: Path) -> bool:
    return path.is_file() and set(SUBSET_COLUMNS) <= set(_header(path).split(","))


def _csv_files(path: Path) -> list[Path]:
    if path.is_file():
        return [path]
    if _is_subset(path / SUBSET_FILE):
        return [path / SUBSET_FILE]
    return sorted(p for p in path.rglob("GT-*.csv") if _is_gt(p))


def class_names(folder: Path) -> dict[int, str]:
    """``{class id: name}`` from ``GTSRB_Class_Names.csv`` in ``folder`` (empty if absent).

    The file has a title line, a header ``Ordner_Name;Klasse``, then ``id;name`` lines.
    """
    file = folder / NAMES_FILE
    if not file.is_file():
        return {}
    names = {}
    for number, line in enumerate(read_text(file).splitlines(), 1):
        first, sep, name = line.strip().partition(";")
        if sep and first.strip().isdecimal():
            names[int(first)] = name.strip()
        elif sep and number > 2:
            raise DatasetError(
                file, f"expected 'class id;name', got {line.strip()!r}", f"line {number}"
            )
    return names


class Gtsrb(DatasetFormat):
    name = "gtsrb"
    summary = "GTSRB CSV (GT-*.csv semicolon files, or the 35px subset's labels.csv)"
    section = "Stallkamp et al. 2012; benchmark.ini.rub.de (GTSRB annotation format)"

    def sniff(self, path: Path) -> bool:
        path = Path(path)
        if path.is_file():
            return _is_gt(path) or _is_subset(path)
        return path.is_dir() and bool(_csv_files(path))

    def read(self, path: Path, images: Path | None = None) -> Dataset:
        path = Path(path)
        files = _csv_files(path) if path.exists() else []
        if not files:
            raise DatasetError(path, "no GTSRB CSV (GT-*.csv or labels.csv) found")
        samples = []
        for file in files:
            names = class_names(file.parent) or class_names(path if path.is_dir() else file.parent)
            read = _read_subset if _is_subset(file) else _read_gt
            samples.extend(read(file, images, names))
        root = path if path.is_dir() else path.parent
        return Dataset(
            root.name,
            tuple(samples),
            self.name,
            str(root),
            {"task": "sign-classification", "box": "roi"},
        )


def _rows(file: Path, delimiter: str, columns: tuple[str, ...]):
    reader = csv.DictReader(io.StringIO(read_text(file), newline=""), delimiter=delimiter)
    missing = [c for c in columns if c not in (reader.fieldnames or ())]
    if missing:
        raise DatasetError(file, f"missing column(s) {', '.join(missing)}", "line 1")
    for row in reader:
        where = f"line {reader.line_num}"
        if any(row.get(c) is None for c in columns):
            raise DatasetError(
                file,
                f"expected {len(reader.fieldnames or ())} '{delimiter}'-separated fields",
                where,
            )
        yield where, row


def _class_id(file: Path, value: str, where: str) -> int:
    if not value.strip().isdecimal():
        raise DatasetError(file, f"class id must be a non-negative integer, got {value!r}", where)
    return int(value)


def _sign(
    file: Path, where: str, source: str, class_id: int, name: str, roi: list[str], size: dict
) -> Sample:
    bbox = checked_box(roi, file, where)
    return Sample(source, (annotation(bbox, name, name, class_id=class_id),), **size)


def _read_gt(file: Path, images: Path | None, names: dict[int, str]) -> list[Sample]:
    samples = []
    for where, row in _rows(file, ";", GT_COLUMNS):
        class_id = _class_id(file, row["ClassId"], where)
        try:
            size = {"width": int(row["Width"]), "height": int(row["Height"])}
        except ValueError:
            raise DatasetError(file, "Width/Height must be integers", where) from None
        samples.append(
            _sign(
                file,
                where,
                resolve_image(file.parent, row["Filename"], images),
                class_id,
                names.get(class_id, str(class_id)),
                [row[f"Roi.{k}"] for k in ("X1", "Y1", "X2", "Y2")],
                size,
            )
        )
    return samples


def _read_subset(file: Path, images: Path | None, names: dict[int, str]) -> list[Sample]:
    samples = []
    for where, row in _rows(file, ",", SUBSET_COLUMNS):
        class_id = _class_id(file, row["class_id"], where)
        name = names.get(class_id) or row.get("class_name_de") or str(class_id)
        roi = [row[f"roi_{k}_35px"] for k in ("x1", "y1", "x2", "y2")]
        samples.append(
            _sign(
                file,
                where,
                resolve_image(file.parent, row["file"], images),
                class_id,
                name,
                roi,
                {"width": 35, "height": 35},
            )
        )
    return samples


@hookimpl
def register_dataset_formats(register):
    register(Gtsrb)
