"""The built-in metrics, registered through ``register_metrics`` like a third-party metric.

The registry loads this module as an internal plugin (always, whatever ``TSRKIT_LOAD_PLUGINS``
says), so every report has the sections ``report.json`` keeps (the README lists them).
"""

from tsrkit.eval.categories import LightingBySize
from tsrkit.eval.coco import CocoAP
from tsrkit.eval.notes import FrameNotes
from tsrkit.eval.overlap import OverlapPR
from tsrkit.eval.perframe import ZhengPerFrame
from tsrkit.eval.state import StateMetric
from tsrkit.plugin.hookspecs import hookimpl

__all__ = ["register_metrics"]


@hookimpl
def register_metrics(register):
    for metric in (ZhengPerFrame, OverlapPR, CocoAP, StateMetric, LightingBySize, FrameNotes):
        register(metric)
