"""Mapping raw dataset labels onto :data:`tsrkit.core.types.STATES`.

Readers keep the raw label in ``Annotation.attributes["label"]`` and set ``state`` with
:func:`to_state`. A registry entry (``states:`` in ``datasets.yaml``) or a caller may give an
explicit ``{raw label: state}`` mapping that overrides the default rules below.
"""

from __future__ import annotations

from collections.abc import Mapping

from tsrkit.core.types import STATES

__all__ = ["PREFIXES", "check_mapping", "to_state"]

#: Label words (lower case, as a prefix of the raw label) and the state they mean. Prefix
#: matching maps e.g. Bosch ``RedLeft`` to red, LISA ``goLeft`` to green, ``warningLeft`` to
#: yellow. ``left`` alone (the Korean Roboflow arrow) is NOT here: its colour is a dataset fact
#: and belongs in that dataset's registry entry.
PREFIXES = (
    ("red_yellow", "red_yellow"),
    ("redyellow", "red_yellow"),
    ("red-yellow", "red_yellow"),
    ("red", "red"),
    ("stop", "red"),
    ("yellow", "yellow"),
    ("amber", "yellow"),
    ("warning", "yellow"),
    ("green", "green"),
    ("go", "green"),
    ("off", "off"),
    ("dark", "off"),
    ("black", "off"),
)


def to_state(label: str, mapping: Mapping[str, str] | None = None) -> str:
    """The signal state a raw ``label`` stands for.

    An explicit ``mapping`` wins (keys compared as given, then lower-cased); otherwise the
    first of :data:`PREFIXES` that starts the lower-cased label; otherwise ``"unknown"``.

    Examples
    --------
    >>> to_state("GreenStraightLeft"), to_state("stop"), to_state("left")
    ('green', 'red', 'unknown')
    >>> to_state("red_yellow")
    'red_yellow'
    >>> to_state("left", {"left": "green"})
    'green'
    """
    text = str(label).strip()
    if mapping:
        for key in (text, text.lower()):
            if key in mapping:
                return mapping[key]
    lower = text.lower()
    for prefix, state in PREFIXES:
        if lower.startswith(prefix):
            return state
    return "unknown"


def check_mapping(mapping: Mapping[str, str], owner: str) -> dict[str, str]:
    """Validate a ``{raw label: state}`` mapping; every value must be one of STATES."""
    if not isinstance(mapping, Mapping):
        raise ValueError(f"{owner}: 'states' must be a mapping of label: state")
    bad = {k: v for k, v in mapping.items() if v not in STATES}
    if bad:
        raise ValueError(f"{owner}: states {bad} are not among {', '.join(STATES)}")
    return {str(k): str(v) for k, v in mapping.items()}
