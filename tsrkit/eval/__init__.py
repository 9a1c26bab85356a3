"""Evaluation: the metrics (Zheng per-frame, lighting x size, IoU, COCO AP, states), their
settings, matching, statistics and the lighting of a frame; beside ``datasets``, below the runs."""

__all__: list[str] = []
