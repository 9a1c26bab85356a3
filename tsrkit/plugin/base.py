"""Base classes a plugin subclasses: Detector, Verifier, Classifier, Tracker, DatasetFormat,
Metric and ReportWriter; and the :class:`Trainable` protocol of plugins ``tsrkit train`` fits.

A subclass sets the class attributes ``name``, ``summary``, ``section`` (the document section it
implements) and ``PARAMS`` (its parameter schema: a tuple of :class:`tsrkit.plugin.params.Param`),
then
implements the one method of its kind. The core validates parameters against ``PARAMS`` before
calling ``__init__``, so the instance's ``params`` always holds every declared key with a
checked value; a plugin-typed parameter (:data:`tsrkit.plugin.params.PLUGIN_TYPES`) holds the
:class:`tsrkit.plugin.params.Part` the core built from its spec.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Protocol, runtime_checkable

from tsrkit.core.records import FrameRecord
from tsrkit.core.results import MetricResult
from tsrkit.core.types import Candidate, Dataset, Detection, Frame, Sample
from tsrkit.plugin.params import Param

if TYPE_CHECKING:
    from tsrkit.eval.settings import EvalSettings
    from tsrkit.plugin.models import Model
    from tsrkit.reporting.report import RunResult

__all__ = [
    "Classifier",
    "DatasetFormat",
    "Detector",
    "Metric",
    "Plugin",
    "ReportWriter",
    "Tracker",
    "Trainable",
    "Verifier",
    "is_trainable",
]


class Plugin(ABC):  # noqa: B024 - the ABC metaclass serves the kinds' abstract methods
    """Common part of every plugin kind."""

    kind: ClassVar[str] = ""
    name: ClassVar[str] = ""
    summary: ClassVar[str] = ""
    section: ClassVar[str] = ""
    PARAMS: ClassVar[tuple[Param, ...]] = ()
    #: Set when the plugin's own version differs from its distribution's.
    version: ClassVar[str | None] = None
    #: What the plugin has to say about the frame it last processed (e.g. that it fell back to
    #: a simpler model); the pipeline copies it into the frame's record and reports count it.
    notes: tuple[str, ...] = ()

    def __init__(self, **params: Any) -> None:
        #: The validated values of :attr:`PARAMS`, by name.
        self.params: dict[str, Any] = params

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.params!r})"


class Detector(Plugin):
    """Finds candidate lit lenses in a frame. Detectors are stateless between frames.

    A trainable detector is also :class:`Trainable` and reads a saved model from its ``model``
    parameter.
    """

    kind = "detector"

    @abstractmethod
    def detect(self, frame: Frame) -> list[Candidate]:
        """Return the candidates of ``frame``, best first."""


class Verifier(Plugin):
    """Rescores or rejects the candidates of any detector (the stage after detection).

    A verifier may also add facts to a candidate, such as its housing box
    (:attr:`tsrkit.core.types.Candidate.housing`). A trainable verifier is :class:`Trainable`: its
    ``fit`` receives the detector whose candidates it learns to verify.
    """

    kind = "verifier"

    @abstractmethod
    def verify(self, frame: Frame, candidates: Sequence[Candidate]) -> list[Candidate]:
        """Return the candidates kept, rescored and possibly refined, best first."""


class Classifier(Plugin):
    """Assigns a state to each candidate of a frame.

    A trainable classifier is :class:`Trainable` and reads a saved model from its ``model``
    parameter (falling back to a default model it ships).
    """

    kind = "classifier"
    #: The states this classifier can output (besides ``"unknown"``); an instance may narrow
    #: them to what its model knows.
    states: tuple[str, ...] = ("red", "yellow", "green")

    @abstractmethod
    def classify(self, frame: Frame, candidates: Sequence[Candidate]) -> list[Detection]:
        """Return one :class:`Detection` per candidate, in the same order."""


class Tracker(Plugin):
    """Carries detections through the frames of one video."""

    kind = "tracker"

    @abstractmethod
    def reset(self) -> None:
        """Forget every track (a new video starts)."""

    def needs_detection(self) -> bool:
        """Whether the detector must run on the next frame (False while tracking suffices)."""
        return True

    @abstractmethod
    def update(self, frame: Frame, detections: Sequence[Detection]) -> list[Detection]:
        """Take this frame's detections; return what is reported for the frame.

        Tracked objects come back with ``origin="tracked"`` and a ``track_id``.
        """


class DatasetFormat(Plugin):
    """Reads (and optionally writes) one annotation format."""

    kind = "format"
    #: Whether :meth:`write` is implemented.
    writable: ClassVar[bool] = False

    @abstractmethod
    def sniff(self, path: Path) -> bool:
        """True when ``path`` (file or folder) is unambiguously in this format."""

    @abstractmethod
    def read(self, path: Path, images: Path | None = None) -> Dataset:
        """Read the annotations at ``path``; image paths resolve against ``images`` if given.

        Raises
        ------
        tsrkit.datasets.DatasetError
            Naming the file, the line or entry, and the problem.
        """

    def write(self, dataset: Dataset, out: Path) -> None:
        """Write ``dataset`` in this format at ``out`` (only when ``writable``)."""
        raise TypeError(f"format '{self.name}' cannot be written")


class Metric(Plugin):
    """A figure of ``report.json``: fed one frame at a time, computed at the end.

    :meth:`reset` starts an evaluation with its settings (dataset, IoU threshold, which box
    is evaluated, whether false positives count); :meth:`update` folds in one frame's ground
    truth and record; :meth:`compute` returns a :class:`~tsrkit.core.results.MetricResult` of
    the class :attr:`result_type`: the report sections, e.g. ``{"iou50": {...}}``, that know
    their headline figures, tables and plots, so that every report writer shows them. Sections
    that two metrics share (``iou50``) are merged key by key.
    """

    kind = "metric"
    #: The class of what :meth:`compute` returns; ``tsrkit report`` rebuilds it from
    #: ``report.json``. The base class shows every figure of the sections in one table.
    result_type: ClassVar[type[MetricResult]] = MetricResult

    @abstractmethod
    def reset(self, settings: EvalSettings) -> None:
        """Forget every frame; the next :meth:`update` starts a new evaluation."""

    @abstractmethod
    def update(self, sample: Sample, record: FrameRecord) -> None:
        """Fold in one evaluated frame: ``sample`` is the ground truth, ``record`` the result."""

    @abstractmethod
    def compute(self) -> MetricResult | Mapping[str, Any]:
        """The result of the frames seen so far (a plain mapping is taken as the sections of a
        :attr:`result_type`)."""


class ReportWriter(Plugin):
    """Writes files of a benchmark's output folder from the finished run.

    :meth:`files` names what :meth:`write` will write (paths relative to the folder), so that
    ``report.json`` can list every file before any is written. Writers with ``default =
    False`` run only when asked for by name (``benchmark(writers=[...])``, ``--writer``).
    """

    kind = "writer"
    #: Whether the writer runs when no writer list is given.
    default: ClassVar[bool] = True

    @abstractmethod
    def files(self, run: RunResult) -> list[str]:
        """The paths (relative to the output folder) :meth:`write` writes for ``run``."""

    @abstractmethod
    def write(self, run: RunResult, folder: Path) -> None:
        """Write the files into ``folder`` (atomically, :mod:`tsrkit.core.atomic`)."""

    def write_comparison(self, folder: Path) -> list[str]:
        """Write files of a ``compare`` folder (its ``compare.json`` and run folders are
        there) and return their names; by default none."""
        return []


@runtime_checkable
class Trainable(Protocol):
    """A plugin ``tsrkit train`` can fit: one signature for every kind.

    ``detector`` is given to a trainable verifier (it learns to verify that detector's
    candidates: ``tsrkit train NAME --detector X``); detectors and classifiers ignore it.
    """

    def fit(self, samples: Iterable[Sample], *, detector: Detector | None = None) -> Model:
        """Fit on annotated ``samples``; return the model to save."""
        ...


def is_trainable(cls: type[Plugin]) -> bool:
    """True when the plugin class can be fitted with ``tsrkit train``."""
    return callable(getattr(cls, "fit", None))
