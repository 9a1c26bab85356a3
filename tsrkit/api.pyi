"""Type stub of :mod:`tsrkit.api`: the plugin API's names and where they live (one list,
read by type checkers and by ``lazy_loader``; the imports are relative to
the package :mod:`tsrkit`)."""

from .core.atomic import (
    atomic_open as atomic_open,
    json_line as json_line,
    write_json as write_json,
)
from .core.depth import (
    PANEL_HEIGHT_M as PANEL_HEIGHT_M,
    distance_from_height as distance_from_height,
)
from .core.errors import (
    TsrkitError as TsrkitError,
)
from .core.geometry import (
    Box as Box,
    box_centre as box_centre,
    circle_box as circle_box,
    clip_box as clip_box,
    iou_matrix as iou_matrix,
    xywh_to_xyxy as xywh_to_xyxy,
    xyxy_to_xywh as xyxy_to_xywh,
)
from .core.images import (
    ImageReadError as ImageReadError,
    read_image as read_image,
)
from .core.records import (
    DetectionRecord as DetectionRecord,
    FrameRecord as FrameRecord,
)
from .core.results import (
    Figure as Figure,
    MetricResult as MetricResult,
    Plot as Plot,
    Table as Table,
)
from .core.types import (
    STATES as STATES,
    WINDOW as WINDOW,
    Annotation as Annotation,
    Candidate as Candidate,
    Dataset as Dataset,
    Detection as Detection,
    Frame as Frame,
    Sample as Sample,
    Skipped as Skipped,
)
from .core.views import (
    FrameViews as FrameViews,
)
from .datasets import (
    open_dataset as open_dataset,
    open_datasets as open_datasets,
    to_state as to_state,
)
from .datasets.errors import (
    DatasetError as DatasetError,
    read_json as read_json,
    read_text as read_text,
    read_yaml as read_yaml,
)
from .datasets.imagesize import (
    image_size as image_size,
)
from .eval.categories import (
    CategoriesResult as CategoriesResult,
    category_table as category_table,
    radius_label as radius_label,
    recall_sort_key as recall_sort_key,
)
from .eval.coco import (
    CocoResult as CocoResult,
    coco_ap as coco_ap,
    coco_dataset as coco_dataset,
    coco_frame as coco_frame,
    coco_run as coco_run,
)
from .eval.matching import (
    centre_hits as centre_hits,
    greedy_match as greedy_match,
)
from .eval.notes import (
    FrameNotesResult as FrameNotesResult,
)
from .eval.overlap import (
    OverlapResult as OverlapResult,
    OverlapScore as OverlapScore,
    score_overlap as score_overlap,
    summarise_overlap as summarise_overlap,
)
from .eval.perframe import (
    FrameScore as FrameScore,
    PerFrameResult as PerFrameResult,
    frame_score as frame_score,
    headline_intervals as headline_intervals,
    summarise as summarise,
)
from .eval.settings import (
    NOT_DETECTION as NOT_DETECTION,
    EvalSettings as EvalSettings,
    eval_settings as eval_settings,
)
from .eval.state import (
    StateResult as StateResult,
    discriminative_ratio as discriminative_ratio,
    state_metrics as state_metrics,
)
from .eval.stats import (
    format_p as format_p,
)
from .geo.gps import (
    Track as Track,
    read_track as read_track,
)
from .plugin.base import (
    Classifier as Classifier,
    DatasetFormat as DatasetFormat,
    Detector as Detector,
    Metric as Metric,
    Plugin as Plugin,
    ReportWriter as ReportWriter,
    Tracker as Tracker,
    Trainable as Trainable,
    Verifier as Verifier,
)
from .plugin.hookspecs import (
    hookimpl as hookimpl,
)
from .plugin.models import (
    Model as Model,
    ModelError as ModelError,
    load_model as load_model,
    save_model as save_model,
)
from .plugin.params import (
    PLUGIN_TYPES as PLUGIN_TYPES,
    Param as Param,
    ParamError as ParamError,
    Part as Part,
    parse_assignments as parse_assignments,
    validate as validate,
)
from .reporting.report import (
    RunResult as RunResult,
    figure_notes as figure_notes,
    fmt as fmt,
    heading as heading,
    headline as headline,
    headline_rows as headline_rows,
    headline_table as headline_table,
    markdown_table as markdown_table,
    title as title,
)
from .reporting.runfolder import (
    read_comparison as read_comparison,
)
from .runner.inputs import (
    IMAGE_EXTENSIONS as IMAGE_EXTENSIONS,
)
from .sun.relative import (
    frame_facts as frame_facts,
    sun_view as sun_view,
)
from .synth import (
    SynthOptions as SynthOptions,
    render_frame as render_frame,
)
from .synth.heads import (
    scatter_heads as scatter_heads,
)
