"""The small immutable values that flow between tsrkit's stages.

Images are NumPy arrays, BGR uint8, as OpenCV reads them. Coordinates are pixels, x right and
y down; boxes are ``(x_min, y_min, x_max, y_max)``. The README's "Where things live" shows the data
path.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from tsrkit.core.files import not_regular
from tsrkit.core.geometry import Box, box_centre, circle_box, inscribed_circle
from tsrkit.core.images import ImageReadError, read_image
from tsrkit.core.records import DetectionRecord
from tsrkit.core.views import FrameViews

__all__ = [
    "STATES",
    "WINDOW",
    "Annotation",
    "Candidate",
    "Dataset",
    "Detection",
    "Frame",
    "Sample",
    "Skipped",
]

#: The signal states every classifier and dataset reader maps its labels onto. ``red_yellow``
#: is the red+amber phase (Germany, UK...) where a dataset labels it.
STATES = ("red", "yellow", "green", "red_yellow", "off", "unknown")

#: The :attr:`Frame.metadata` key of a frame that is a window of a larger frame (what
#: :class:`tsrkit.runner.follow.Follower` searches between key frames): ``(x0, y0, width,
#: height)``, the window's top-left corner in the larger frame and that frame's size, pixels.
WINDOW = "window"


@dataclass(frozen=True)
class Candidate:
    """A place a detector believes holds a lit lens.

    Parameters
    ----------
    x, y : float
        Centre in pixels.
    radius : float
        Lens radius in pixels.
    bbox : tuple of float
        ``(x_min, y_min, x_max, y_max)``.
    score : float
        The detector's confidence or saliency; higher is more likely (scale is the detector's).
    state : str or None
        A state the detector itself can tell (e.g. TL-recognizer's colour filters), else None.
    housing : tuple of float or None
        The signal housing around the lens, ``(x_min, y_min, x_max, y_max)``, once a housing
        stage has fitted one; ``bbox`` stays a lens box (that stage's measured lit lens).
    housing_score : float or None
        How well that housing fits, in [0, 1].
    distance_m : float or None
        Distance from the camera in metres, when the detector knows the target's real size
        (:func:`tsrkit.core.depth.distance_from_height`).
    """

    x: float
    y: float
    radius: float
    bbox: Box
    score: float
    state: str | None = None
    housing: Box | None = None
    housing_score: float | None = None
    distance_m: float | None = None

    @property
    def lens_bbox(self) -> Box:
        """The lens box: the detector's, or the lit lens a housing stage fitted around."""
        return self.bbox

    @property
    def object_bbox(self) -> Box:
        """The box a record reports: the housing when one was fitted, else the lens box."""
        return self.housing if self.housing is not None else self.bbox

    @classmethod
    def from_circle(
        cls, x: float, y: float, radius: float, score: float, state: str | None = None
    ) -> Candidate:
        """Build a candidate whose box circumscribes the circle ``(x, y, radius)``."""
        return cls(float(x), float(y), float(radius), circle_box(x, y, radius), float(score), state)

    @classmethod
    def from_box(cls, bbox: Sequence[float], score: float, state: str | None = None) -> Candidate:
        """Build a candidate centred in ``bbox`` with the radius of its inscribed circle."""
        x, y, radius = inscribed_circle(bbox)
        x0, y0, x1, y1 = (float(v) for v in bbox)
        return cls(x, y, radius, (x0, y0, x1, y1), float(score), state)


@dataclass(frozen=True)
class Detection:
    """A candidate with its classified state.

    ``origin`` is ``"detected"`` for a detector's output and ``"tracked"`` when a tracker
    carried it over from earlier frames; ``track_id`` links the records of one tracked object.
    """

    candidate: Candidate
    state: str
    state_scores: Mapping[str, float] = field(default_factory=dict)
    origin: str = "detected"
    track_id: int | None = None

    def to_record(self) -> dict[str, Any]:
        """The JSON object ``tsrkit detect`` writes for this detection.

        ``bbox`` is the housing when a housing stage fitted one, else the lens box;
        ``lens_bbox`` is always the lens box (:class:`tsrkit.core.records.DetectionRecord`).
        """
        return DetectionRecord.from_detection(self).to_json()


@dataclass(frozen=True)
class Annotation:
    """A ground-truth box with its state and any reader-specific attributes."""

    bbox: Box
    state: str
    attributes: Mapping[str, Any] = field(default_factory=dict)

    @property
    def center(self) -> tuple[float, float]:
        """Centre of the box."""
        return box_centre(self.bbox)


@dataclass(frozen=True, eq=False)
class Frame:
    """One image, with where it came from.

    ``index`` is the frame number inside a video (0 for a still image); ``timestamp`` is in
    seconds when known. ``metadata`` carries optional camera facts that some methods use
    (``focal_px``, ``pitch_deg``, ``roll_deg``, ``distance_m``, ``lighting``...).
    """

    image: np.ndarray
    source: str
    index: int = 0
    timestamp: float | None = None
    metadata: Mapping[str, Any] = field(default_factory=dict)
    #: Colour conversions and per-pixel maps of ``image``, computed once for every stage
    #: (:mod:`tsrkit.core.views`); a frame made with ``dataclasses.replace`` starts its own.
    views: FrameViews = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "views", FrameViews(self.image))

    def band(self, rows: int) -> Frame:
        """The frame's upper ``rows`` rows, whose views slice what this frame's hold."""
        upper = Frame(self.image[:rows], self.source, self.index, self.timestamp, self.metadata)
        object.__setattr__(upper, "views", FrameViews(upper.image, parent=self.views))
        return upper

    @property
    def height(self) -> int:
        """Image height in pixels."""
        return int(self.image.shape[0])

    @property
    def width(self) -> int:
        """Image width in pixels."""
        return int(self.image.shape[1])


@dataclass(frozen=True)
class Skipped:
    """An input that could not be used, and why."""

    source: str
    reason: str


@dataclass(frozen=True)
class Sample:
    """One annotated image of a dataset; the pixels are read only when :meth:`load` is called.

    ``image`` may hold the pixels directly (generated or in-memory data); otherwise ``source`` is
    the path to read. ``split`` is ``"train"``, ``"valid"``, ``"test"`` or None.
    """

    source: str
    annotations: tuple[Annotation, ...] = ()
    width: int | None = None
    height: int | None = None
    split: str | None = None
    metadata: Mapping[str, Any] = field(default_factory=dict)
    image: np.ndarray | None = field(default=None, repr=False, compare=False)

    def load(self) -> Frame:
        """Read the image (BGR uint8) and return it as a :class:`Frame`.

        Raises
        ------
        tsrkit.core.images.ImageReadError
            When the file is missing or not a decodable image.
        """
        image = self.image if self.image is not None else read_image(self.source)
        return Frame(image=image, source=self.source, metadata=self.metadata)

    def hash_into(self, digest) -> None:
        """Feed the image to a ``hashlib`` digest: the file's bytes, or the in-memory pixels
        and their shape (the cache key and the training-set checksum).

        Raises
        ------
        tsrkit.core.images.ImageReadError
            The file is not a regular file (a FIFO, a device, a folder, missing).
        OSError
            It cannot be read.
        """
        if self.image is not None:
            digest.update(repr(self.image.shape).encode())
            digest.update(self.image.tobytes())
            return
        problem = not_regular(self.source)
        if problem:  # a FIFO would block the read, a device never end it
            raise ImageReadError(f"{self.source}: {problem}")
        with open(self.source, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                digest.update(block)


@dataclass(frozen=True)
class Dataset:
    """An ordered collection of annotated samples plus facts about where it came from.

    ``info`` holds registry facts (licence, citation, box convention: ``"lens"`` or
    ``"housing"``...). Images are not held in memory; iterate and call ``Sample.load``.
    """

    name: str
    samples: tuple[Sample, ...]
    format: str = ""
    root: str = ""
    info: Mapping[str, Any] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.samples)

    def __iter__(self):
        return iter(self.samples)

    def split(self, name: str) -> Dataset:
        """The samples of one split (``train``, ``valid``, ``test``) as a new dataset."""
        chosen = tuple(s for s in self.samples if s.split == name)
        return Dataset(f"{self.name}:{name}", chosen, self.format, self.root, self.info)
