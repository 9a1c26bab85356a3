"""Evaluation: what the metrics compute and show (Zheng per-frame, lighting x size, IoU, COCO AP,
states; the metrics are plugins, ``plugins/metrics/``), settings, matching, statistics, lighting."""

__all__: list[str] = []
