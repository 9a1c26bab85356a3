"""The plugin API: everything a tsrkit plugin, built-in or third-party, imports from the core.

This module is the stable surface. A plugin module imports the core only from here::

    from tsrkit.api import Candidate, Detector, Frame, Param, hookimpl

and receives the plugins it builds on (a ``union``'s members, a verifier's stage before it)
as parameters resolved by the core (:data:`PLUGIN_TYPES`), never from the registry.
Every other core module is implementation: it may change between releases.
``tests/core/test_plugin_api.py`` enforces the boundary for the plugins shipped with tsrkit
and the example package.

The names, by what they are for:

- plugin kinds and hooks: :class:`Detector`, :class:`Verifier`, :class:`Classifier`,
  :class:`Tracker`, :class:`DatasetFormat`, :class:`Metric`, :class:`ReportWriter`,
  :class:`Trainable`, :class:`Plugin`, :data:`hookimpl`;
- parameters: :class:`Param`, :class:`ParamError`, :class:`Part`, :data:`PLUGIN_TYPES`,
  :func:`validate`, :func:`parse_assignments`;
- types: :class:`Frame` (and its shared colour views, :class:`FrameViews`), :class:`Candidate`,
  :class:`Detection`, :class:`Annotation`, :class:`Sample`, :class:`Dataset`, :class:`Skipped`,
  :data:`STATES`, :data:`WINDOW` (where a frame's window lies in a larger frame),
  :class:`FrameRecord`, :class:`DetectionRecord`, :class:`RunResult`;
- geometry: :data:`Box`, :func:`box_centre`, :func:`circle_box`, :func:`clip_box`,
  :func:`iou_matrix`, :func:`xywh_to_xyxy`, :func:`xyxy_to_xywh`;
- files and errors: :func:`atomic_open`, :func:`write_json`, :func:`json_line`,
  :func:`read_text`, :func:`read_json`, :func:`read_yaml`, :func:`read_image`,
  :func:`image_size`,
  :data:`IMAGE_EXTENSIONS`, :class:`TsrkitError`, :class:`DatasetError`,
  :class:`ImageReadError`;
- models: :class:`Model`, :class:`ModelError`, :func:`load_model`, :func:`save_model`;
- datasets: :func:`open_dataset`, :func:`open_datasets`, :func:`to_state`;
- evaluation: :class:`EvalSettings`, :func:`eval_settings`, :func:`centre_hits`,
  :func:`greedy_match`, :func:`frame_score`, :func:`radius_label`,
  :func:`recall_sort_key`, :func:`discriminative_ratio`, :func:`coco_run`;
- metric results, which every report writer renders: :class:`MetricResult` (a metric's
  ``compute`` returns one) with its :class:`Figure` (headline), :class:`Table` and
  :class:`Plot` parts;
- what the built-in metrics (``plugins/metrics/``) compute and return: :data:`NOT_DETECTION`,
  :class:`FrameScore`, :func:`summarise`, :func:`headline_intervals`, :class:`PerFrameResult`,
  :func:`category_table`, :class:`CategoriesResult`, :class:`OverlapScore`,
  :func:`score_overlap`, :func:`summarise_overlap`, :class:`OverlapResult`, :func:`coco_frame`,
  :func:`coco_dataset`, :func:`coco_ap`, :class:`CocoResult`, :func:`state_metrics`,
  :class:`StateResult`, :class:`FrameNotesResult`;
- reports: :class:`RunResult`, :func:`heading`, :func:`headline`, :func:`headline_rows`,
  :func:`headline_table`, :func:`figure_notes`, :func:`fmt`, :func:`format_p`,
  :func:`markdown_table`, :func:`title`, :func:`read_comparison`;
- scene facts and synthetic scenes: :data:`PANEL_HEIGHT_M`, :func:`distance_from_height`,
  :func:`frame_facts`, :func:`sun_view`, :class:`Track`, :func:`read_track`,
  :class:`SynthOptions`, :func:`render_frame`, :func:`scatter_heads`.

Names are imported on first use (PEP 562), so that loading a plugin costs only what it uses.
"""

from __future__ import annotations

import lazy_loader as _lazy

# The stub's imports are relative to the package (``from .core.types import Frame``), as
# lazy_loader reads them: each name resolves against ``tsrkit`` on first use.
__getattr__, __dir__, __all__ = _lazy.attach_stub("tsrkit", __file__)
