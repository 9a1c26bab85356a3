"""Pascal VOC XML (one ``<annotation>`` file per image): read and write.

Read from one XML file, a folder of them, or a VOC root with ``Annotations/`` (then
``ImageSets/Main/{train,val,test}.txt`` give the splits). Boxes are taken as written
(``xmin ymin xmax ymax``; VOC's 1-based pixel convention is not shifted). The image is
``--images``/filename when given, else ``<path>`` when it exists (relative to the XML's folder),
else the filename beside the XML, else in ``../JPEGImages``. The writer stores ``<path>``
relative to the XML folder and adds a ``<state>`` element when the state is not what the
``<name>`` label maps to; VOC readers ignore unknown elements.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import defusedxml.ElementTree as SafeET
from defusedxml import DefusedXmlException

from tsrkit.api import (
    Dataset,
    DatasetError,
    DatasetFormat,
    Sample,
    atomic_open,
    hookimpl,
    read_text,
    to_state,
)
from tsrkit_plugins.formats.common import (
    absolute,
    annotation,
    checked_box,
    explicit_state,
    raw_label,
    unique_path,
)
from tsrkit_plugins.shared.paths import relative_source

ANNOTATIONS = "Annotations"
SETS = Path("ImageSets") / "Main"
SPLIT_FILES = {"train": "train", "val": "valid", "test": "test"}
COORDS = ("xmin", "ymin", "xmax", "ymax")
FLAGS = ("difficult", "truncated", "occluded")


def _xml_files(path: Path) -> list[Path]:
    if path.is_file():
        return [path]
    folder = path / ANNOTATIONS if (path / ANNOTATIONS).is_dir() else path
    return sorted(folder.glob("*.xml"))


def _is_voc(file: Path) -> bool:
    try:
        for _, element in SafeET.iterparse(file, events=("start",)):
            return element.tag == "annotation"
    except (ET.ParseError, DefusedXmlException):
        return False
    return False


class Voc(DatasetFormat):
    name = "voc"
    summary = "Pascal VOC XML annotations (Annotations/ + ImageSets/Main), read and write"
    section = "host.robots.ox.ac.uk/pascal/VOC (devkit annotation format)"
    writable = True

    def sniff(self, path: Path) -> bool:
        path = Path(path)
        if path.is_file() and path.suffix.lower() != ".xml":
            return False
        files = _xml_files(path) if path.exists() else []
        return bool(files) and _is_voc(files[0])

    def read(self, path: Path, images: Path | None = None) -> Dataset:
        path = Path(path)
        files = _xml_files(path)
        if not files:
            raise DatasetError(path, "no .xml annotation files found")
        for file in files:
            if not file.is_file():  # a FIFO or device would block the XML parser
                raise DatasetError(file, "not a regular file")
        root = path if path.is_dir() else path.parent
        splits = _splits(root)
        samples = tuple(_sample(f, images, splits.get(f.stem)) for f in files)
        return Dataset(root.name, samples, self.name, str(root), {})

    def write(self, dataset: Dataset, out: Path) -> None:
        out = Path(out)
        folder = out / ANNOTATIONS
        used: set[Path] = set()
        by_split: dict[str, list[str]] = {}
        for sample in dataset:
            file = unique_path(folder / (Path(sample.source).stem + ".xml"), used)
            with atomic_open(file) as fh:
                ET.ElementTree(_element(sample, folder)).write(fh, encoding="unicode")
            if sample.split:
                by_split.setdefault(sample.split, []).append(file.stem)
        for split_file, split in SPLIT_FILES.items():
            if split in by_split:
                with atomic_open(out / SETS / f"{split_file}.txt") as fh:
                    fh.write("\n".join(by_split[split]) + "\n")


def _splits(root: Path) -> dict[str, str]:
    sets = root / SETS
    out: dict[str, str] = {}
    for split_file, split in SPLIT_FILES.items():
        listed = sets / f"{split_file}.txt"
        if listed.is_file():
            out.update(
                (line.split()[0], split) for line in read_text(listed).splitlines() if line.strip()
            )
    return out


def _parse(file: Path) -> ET.Element:
    try:
        root = SafeET.parse(file).getroot()
    except DefusedXmlException as exc:  # entities and DTDs are refused (billion laughs...)
        raise DatasetError(
            file, f"XML with a forbidden construct ({type(exc).__name__})", "document"
        ) from None
    except ET.ParseError as exc:
        line, column = exc.position
        reason = str(exc).split(":")[0]
        raise DatasetError(
            file, f"not well-formed XML ({reason})", f"line {line} column {column}"
        ) from None
    if root.tag != "annotation":
        raise DatasetError(file, f"root element is <{root.tag}>, expected <annotation>")
    return root


def _text(element: ET.Element, tag: str, file: Path, where: str) -> str:
    found = element.find(tag)
    text = "" if found is None else (found.text or "").strip()
    if not text:
        raise DatasetError(file, f"missing <{tag}>", where)
    return text


def _image(file: Path, root: ET.Element, images: Path | None) -> str:
    filename = _text(root, "filename", file, "<annotation>")
    if images is not None:
        return absolute(images / filename)
    written = (root.findtext("path") or "").strip()
    candidates = ([file.parent / written] if written else []) + [
        file.parent / filename,
        file.parent.parent / "JPEGImages" / filename,
    ]
    chosen = next((c for c in candidates if c.is_file()), file.parent / filename)
    return absolute(chosen)


def _sample(file: Path, images: Path | None, split: str | None) -> Sample:
    root = _parse(file)
    annotations = []
    for i, obj in enumerate(root.iter("object")):
        where = f"<object> {i + 1}"
        label = _text(obj, "name", file, where)
        box = obj.find("bndbox")
        if box is None:
            raise DatasetError(file, "missing <bndbox>", where)
        bbox = checked_box([_text(box, k, file, where) for k in COORDS], file, where)
        flags = {k: int(text) for k in FLAGS if (text := obj.findtext(k) or "").isdecimal()}
        state = explicit_state(
            {"state": obj.findtext("state")} if obj.find("state") is not None else {}, file, where
        )
        annotations.append(annotation(bbox, label, state, **flags))
    width, height = (
        int(text) if (text := (root.findtext(f"size/{k}") or "").strip()).isdecimal() else None
        for k in ("width", "height")
    )
    return Sample(_image(file, root, images), tuple(annotations), width, height, split=split)


def _element(sample: Sample, folder: Path) -> ET.Element:
    root = ET.Element("annotation")
    ET.SubElement(root, "folder").text = Path(sample.source).parent.name
    ET.SubElement(root, "filename").text = Path(sample.source).name
    ET.SubElement(root, "path").text = relative_source(sample.source, folder)
    if sample.width and sample.height:
        size = ET.SubElement(root, "size")
        for key, value in (("width", sample.width), ("height", sample.height), ("depth", 3)):
            ET.SubElement(size, key).text = str(value)
    for ann in sample.annotations:
        obj = ET.SubElement(root, "object")
        label = raw_label(ann)
        ET.SubElement(obj, "name").text = label
        if ann.state != to_state(label):
            ET.SubElement(obj, "state").text = ann.state
        for flag in FLAGS:
            if flag in ann.attributes:
                ET.SubElement(obj, flag).text = str(int(ann.attributes[flag]))
        box = ET.SubElement(obj, "bndbox")
        for key, edge in zip(COORDS, ann.bbox):
            ET.SubElement(box, key).text = f"{float(edge):.3f}".rstrip("0").rstrip(".")
    ET.indent(root)
    return root


@hookimpl
def register_dataset_formats(register):
    register(Voc)
