"""LISA Traffic Light Dataset annotation CSVs (semicolon): ``frameAnnotationsBOX.csv`` (the
whole housing) and ``frameAnnotationsBULB.csv`` (the lit bulb).

Columns: ``Filename;Annotation tag;Upper left corner X;Upper left corner Y;Lower right corner
X;Lower right corner Y;Origin file;Origin frame number;Origin track;Origin track frame number``.
One row per box; rows of the same ``Filename`` form one sample (frames without boxes are not in
these files). Tags map to states: ``stop*`` red, ``warning*`` yellow, ``go*`` green; the raw tag
(e.g. ``goLeft``) stays in ``attributes["label"]``. The image is ``--images``/file name when
given, else ``Filename`` as written, relative to the CSV's folder. A folder is read through every
``frameAnnotations<KIND>.csv`` below it (``kind`` parameter: BOX or BULB).
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

from tsrkit.api import Dataset, DatasetError, DatasetFormat, Param, Sample, hookimpl, read_text
from tsrkit_plugins.formats.common import absolute, annotation, checked_box

COLUMNS = (
    "Filename",
    "Annotation tag",
    "Upper left corner X",
    "Upper left corner Y",
    "Lower right corner X",
    "Lower right corner Y",
)
HEADER = "Filename;Annotation tag"
BOXES = {"BOX": "housing", "BULB": "lens"}


def _is_lisa(path: Path) -> bool:
    if not (path.is_file() and path.suffix.lower() == ".csv"):
        return False
    with open(path, encoding="utf-8", errors="replace") as fh:
        return fh.readline().startswith(HEADER)


class Lisa(DatasetFormat):
    name = "lisa"
    summary = "LISA traffic light CSV (semicolon; frameAnnotationsBOX / BULB files)"
    section = "Jensen et al., IEEE T-ITS 2016 (LISA Traffic Light Dataset)"
    PARAMS = (
        Param(
            "kind",
            "str",
            "BOX",
            choices=("BOX", "BULB"),
            help="Which annotation files a folder is read through",
        ),
    )

    def sniff(self, path: Path) -> bool:
        path = Path(path)
        return _is_lisa(path) or (path.is_dir() and bool(self._files(path)))

    def _files(self, folder: Path) -> list[Path]:
        return sorted(
            p for p in folder.rglob(f"frameAnnotations{self.params['kind']}.csv") if _is_lisa(p)
        )

    def read(self, path: Path, images: Path | None = None) -> Dataset:
        path = Path(path)
        files = [path] if path.is_file() else self._files(path) if path.is_dir() else []
        if not files:
            raise DatasetError(path, "no LISA frameAnnotations CSV found")
        frames: dict[str, list] = {}
        for file in files:
            for source, ann in _rows(file, images):
                frames.setdefault(source, []).append(ann)
        kinds = {k for k in BOXES if any(f.stem.endswith(k) for f in files)}
        box = BOXES[kinds.pop()] if len(kinds) == 1 else "mixed"
        samples = tuple(Sample(source, tuple(anns)) for source, anns in frames.items())
        root = path if path.is_dir() else path.parent
        return Dataset(root.name, samples, self.name, str(root), {"box": box})


def _rows(file: Path, images: Path | None):
    with io.StringIO(read_text(file), newline="") as fh:
        reader = csv.DictReader(fh, delimiter=";")
        missing = [c for c in COLUMNS if c not in (reader.fieldnames or ())]
        if missing:
            raise DatasetError(file, f"missing column(s) {', '.join(missing)}", "line 1")
        for row in reader:
            where = f"line {reader.line_num}"
            if any(row.get(c) in (None, "") for c in COLUMNS):
                raise DatasetError(
                    file,
                    f"empty or missing fields (expected ';'-separated {len(COLUMNS)}+ columns)",
                    where,
                )
            bbox = checked_box([row[c] for c in COLUMNS[2:]], file, where)
            name = row["Filename"]
            image = images / Path(name).name if images is not None else file.parent / name
            extra = {
                k: row[c]
                for k, c in (
                    ("origin_file", "Origin file"),
                    ("origin_frame", "Origin frame number"),
                    ("track", "Origin track"),
                )
                if row.get(c)
            }
            yield absolute(image), annotation(bbox, row["Annotation tag"], **extra)


@hookimpl
def register_dataset_formats(register):
    register(Lisa)
