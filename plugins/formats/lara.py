"""LaRA Traffic Lights Recognition benchmark ground truth (``Lara_UrbanSeq1_GroundTruth_GT.txt``).

After ``#`` comment lines, one box per line:
``timestamp / frameindex x1 y1 x2 y2 id 'Traffic Light' 'subtype'`` with subtype go, stop,
warning or ambiguous (go green, stop red, warning yellow, ambiguous unknown). Lines of the same
frame form one sample, with ``timestamp`` and ``frame`` in its metadata (frames without boxes
are not listed in the file). The image is ``image_pattern`` formatted with the frame index,
relative to the text file's folder (or ``--images``); the sequence is 640x480.
"""

from __future__ import annotations

import shlex
from pathlib import Path

from tsrkit.api import Dataset, DatasetError, DatasetFormat, Param, Sample, hookimpl, read_text
from tsrkit_plugins.formats.common import annotation, checked_box, resolve_image

SUBTYPES = {"go": "green", "stop": "red", "warning": "yellow", "ambiguous": "unknown"}
FIELDS = 10
WIDTH, HEIGHT = 640, 480


def _tokens(file: Path, line: str, where: str) -> list[str]:
    try:
        tokens = shlex.split(line)
    except ValueError as exc:
        raise DatasetError(file, f"cannot split line ({exc})", where) from None
    if len(tokens) != FIELDS or tokens[1] != "/":
        raise DatasetError(
            file,
            "expected \"timestamp / frame x1 y1 x2 y2 id 'type' "
            f"'subtype'\" ({FIELDS} fields), got {len(tokens)}",
            where,
        )
    return tokens


def _lines(file: Path):
    for number, line in enumerate(read_text(file).split("\n"), 1):
        if line.strip() and not line.lstrip().startswith("#"):
            yield number, line


def _is_lara(path: Path) -> bool:
    if not (path.is_file() and path.suffix.lower() == ".txt"):
        return False
    try:
        for number, line in _lines(path):
            _tokens(path, line, f"line {number}")
            return True
    except DatasetError:
        return False
    return False


class Lara(DatasetFormat):
    name = "lara"
    summary = "LaRA traffic lights ground-truth txt (go/stop/warning/ambiguous)"
    section = "LaRA TLR benchmark, Mines ParisTech (Lara_UrbanSeq1_GroundTruth_GT.txt)"
    PARAMS = (
        Param(
            "image_pattern",
            "str",
            "Lara3D_UrbanSeq1_JPG/frame_{frame:06d}.jpg",
            help="Image path of a frame index, relative to the ground-truth file",
        ),
    )

    def sniff(self, path: Path) -> bool:
        return _is_lara(Path(path))

    def read(self, path: Path, images: Path | None = None) -> Dataset:
        file = Path(path)
        if not file.is_file():
            raise DatasetError(file, "ground-truth file not found")
        frames: dict[int, dict] = {}
        for number, line in _lines(file):
            where = f"line {number}"
            tokens = _tokens(file, line, where)
            if tokens[9] not in SUBTYPES:
                raise DatasetError(
                    file,
                    f"unknown subtype {tokens[9]!r} (expected one of {', '.join(SUBTYPES)})",
                    where,
                )
            try:
                timestamp, frame, object_id = float(tokens[0]), int(tokens[2]), int(tokens[7])
            except ValueError:
                raise DatasetError(file, "timestamp, frame and id must be numbers", where) from None
            bbox = checked_box(tokens[3:7], file, where)
            record = frames.setdefault(frame, {"timestamp": timestamp, "annotations": []})
            record["annotations"].append(
                annotation(
                    bbox, tokens[9], SUBTYPES[tokens[9]], object_id=object_id, type=tokens[8]
                )
            )
        samples = tuple(
            Sample(
                resolve_image(
                    file.parent, self.params["image_pattern"].format(frame=frame), images
                ),
                tuple(record["annotations"]),
                WIDTH,
                HEIGHT,
                metadata={"timestamp": record["timestamp"], "frame": frame},
            )
            for frame, record in frames.items()
        )
        return Dataset(file.stem, samples, self.name, str(file.parent), {"box": "housing"})


@hookimpl
def register_dataset_formats(register):
    register(Lara)
