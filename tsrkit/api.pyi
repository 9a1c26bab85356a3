"""Type stub of :mod:`tsrkit.api`: the plugin API's names and where they live (one list,
read by type checkers and by the lazy loader)."""

from tsrkit.atomic import (
    atomic_open as atomic_open,
    json_line as json_line,
    write_json as write_json,
)
from tsrkit.benchmarking import (
    eval_settings as eval_settings,
)
from tsrkit.datasets import (
    open_dataset as open_dataset,
    open_datasets as open_datasets,
    to_state as to_state,
)
from tsrkit.datasets.errors import (
    DatasetError as DatasetError,
    read_json as read_json,
    read_text as read_text,
    read_yaml as read_yaml,
)
from tsrkit.datasets.imagesize import (
    image_size as image_size,
)
from tsrkit.depth import (
    PANEL_HEIGHT_M as PANEL_HEIGHT_M,
    distance_from_height as distance_from_height,
)
from tsrkit.errors import (
    TsrkitError as TsrkitError,
)
from tsrkit.eval.categories import (
    radius_label as radius_label,
    recall_sort_key as recall_sort_key,
)
from tsrkit.eval.coco import (
    coco_run as coco_run,
)
from tsrkit.eval.matching import (
    centre_hits as centre_hits,
    greedy_match as greedy_match,
)
from tsrkit.eval.perframe import (
    frame_score as frame_score,
)
from tsrkit.eval.results import (
    Figure as Figure,
    MetricResult as MetricResult,
    Plot as Plot,
    Table as Table,
)
from tsrkit.eval.settings import (
    EvalSettings as EvalSettings,
)
from tsrkit.eval.state import (
    discriminative_ratio as discriminative_ratio,
)
from tsrkit.eval.stats import (
    format_p as format_p,
)
from tsrkit.geo.gps import (
    Track as Track,
    read_track as read_track,
)
from tsrkit.geometry import (
    Box as Box,
    box_centre as box_centre,
    circle_box as circle_box,
    clip_box as clip_box,
    iou_matrix as iou_matrix,
    xywh_to_xyxy as xywh_to_xyxy,
    xyxy_to_xywh as xyxy_to_xywh,
)
from tsrkit.hookspecs import (
    hookimpl as hookimpl,
)
from tsrkit.images import (
    ImageReadError as ImageReadError,
    read_image as read_image,
)
from tsrkit.inputs import (
    IMAGE_EXTENSIONS as IMAGE_EXTENSIONS,
)
from tsrkit.models import (
    Model as Model,
    ModelError as ModelError,
    load_model as load_model,
    save_model as save_model,
)
from tsrkit.params import (
    PLUGIN_TYPES as PLUGIN_TYPES,
    Param as Param,
    ParamError as ParamError,
    Part as Part,
    parse_assignments as parse_assignments,
    validate as validate,
)
from tsrkit.plugin import (
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
from tsrkit.records import (
    DetectionRecord as DetectionRecord,
    FrameRecord as FrameRecord,
)
from tsrkit.report import (
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
from tsrkit.runfolder import (
    read_comparison as read_comparison,
)
from tsrkit.sun.relative import (
    frame_facts as frame_facts,
    sun_view as sun_view,
)
from tsrkit.synth import (
    SynthOptions as SynthOptions,
    render_frame as render_frame,
)
from tsrkit.synth.heads import (
    scatter_heads as scatter_heads,
)
from tsrkit.types import (
    STATES as STATES,
    Annotation as Annotation,
    Candidate as Candidate,
    Dataset as Dataset,
    Detection as Detection,
    Frame as Frame,
    Sample as Sample,
    Skipped as Skipped,
)
