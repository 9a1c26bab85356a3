"""Type stub of :mod:`tsrkit`: the library's public names and where they live (one list, read
by type checkers and by ``lazy_loader``, which imports each name on first use)."""

from . import (
    api as api,
    cli as cli,
    core as core,
    datasets as datasets,
    eval as eval,
    geo as geo,
    plugin as plugin,
    reporting as reporting,
    runner as runner,
    spatiotemporal as spatiotemporal,
    sun as sun,
    synth as synth,
)
from ._library import (
    benchmark as benchmark,
    classifier as classifier,
    compare as compare,
    dataset as dataset,
    detector as detector,
    plugins as plugins,
    read_frame as read_frame,
    tracker as tracker,
    train as train,
    verifier as verifier,
)
from .core.errors import TsrkitError as TsrkitError
from .core.images import ImageReadError as ImageReadError, read_image as read_image
from .core.records import DetectionRecord as DetectionRecord, FrameRecord as FrameRecord
from .core.types import (
    STATES as STATES,
    Annotation as Annotation,
    Candidate as Candidate,
    Dataset as Dataset,
    Detection as Detection,
    Frame as Frame,
    Sample as Sample,
    Skipped as Skipped,
)
from .core.version import __version__ as __version__
from .eval.settings import EvalSettings as EvalSettings
from .plugin.base import (
    Classifier as Classifier,
    DatasetFormat as DatasetFormat,
    Detector as Detector,
    Metric as Metric,
    ReportWriter as ReportWriter,
    Tracker as Tracker,
    Trainable as Trainable,
    Verifier as Verifier,
)
from .plugin.hookspecs import hookimpl as hookimpl
from .plugin.models import (
    Model as Model,
    ModelError as ModelError,
    load_model as load_model,
    save_model as save_model,
)
from .plugin.params import Param as Param, ParamError as ParamError
from .plugin.pipeline import FrameResult as FrameResult, Pipeline as Pipeline
from .plugin.registry import PluginNotFound as PluginNotFound, get_registry as get_registry
from .plugin.selection import Selection as Selection, select as select
from .reporting.report import RunResult as RunResult
from .runner.inputs import iter_frames as iter_frames
