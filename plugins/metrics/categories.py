"""Metric ``categories``: Zheng 2016's Table 5-2 (frames by lighting and maximum target radius,
with recall and precision columns) and its Figure 5-1 bubbles; the ``categories`` section."""

from __future__ import annotations

from tsrkit.api import CategoriesResult, category_table, hookimpl
from tsrkit_plugins.metrics.per_frame import FrameScoreMetric


class LightingBySize(FrameScoreMetric):
    """``categories``: the Table 5-2 rows (lighting x max target radius) with Figure 5-1 bubbles."""

    name = "categories"
    summary = "frame counts by lighting and max target radius, recall and precision columns"
    section = "Zheng 2016, 5.2.1, Table 5-2, Figure 5-1"

    result_type = CategoriesResult

    def compute(self) -> CategoriesResult:
        return CategoriesResult(
            {"categories": category_table(self.scores) if self.settings.detection else []}
        )


@hookimpl
def register_metrics(register):
    register(LightingBySize)
