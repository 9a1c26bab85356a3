"""Turning per-state scores into a state: the best state, Zheng's discriminative ratio (5.3),
and Lee's fusion of the lights of one approach (5.3.4)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from tsrkit.api import discriminative_ratio as ratio_or_none

UNKNOWN = "unknown"


def best_state(scores: Mapping[str, float]) -> str:
    """The state with the highest score (the first one listed on a tie)."""
    if not scores:
        raise ValueError("no state scores to choose from")
    return max(scores, key=lambda s: scores[s])


def discriminative_ratio(scores: Mapping[str, float]) -> float:
    """``1 - min / max`` over the state scores (Zheng 5.3); 0 when every score is 0.

    Examples
    --------
    >>> discriminative_ratio({"red": 0.8, "yellow": 0.2, "green": 0.4})
    0.75
    """
    return ratio_or_none(scores) or 0.0


def fuse_lights(decisions: Sequence[tuple[str, float]], threshold: float) -> str:
    """The state of an approach from its lights' ``(state, probability)`` (Lee 5.3.4).

    The lights' common state when they all agree; otherwise the state of the most probable
    light; ``unknown`` when that probability is below ``threshold`` or there is no light.

    Examples
    --------
    >>> fuse_lights([("red", 0.4), ("green", 0.9)], threshold=0.5)
    'green'
    """
    if not decisions:
        return UNKNOWN
    states = {state for state, _ in decisions}
    state, probability = max(decisions, key=lambda d: d[1])
    if len(states) == 1 and state != UNKNOWN:
        return state
    return state if probability >= threshold else UNKNOWN
