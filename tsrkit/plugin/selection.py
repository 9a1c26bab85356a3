"""Choosing plugins and routing their parameters: one routine for the Python API, YAML configs
and the command line.

:func:`build` picks the detector, verifier, classifier and tracker (arguments win over the
config, which wins over the default detector) and gives each ``key=value`` to the plugin that
declares ``key``; :func:`build_compare` does the same for several detectors side by side.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from tsrkit.plugin.base import Classifier, Detector, Tracker, Verifier
from tsrkit.plugin.params import ParamError, load_config, parse_assignments
from tsrkit.plugin.pipeline import Pipeline
from tsrkit.plugin.registry import get_registry

__all__ = [
    "DEFAULT_DETECTOR",
    "STAGES",
    "Config",
    "Params",
    "Selection",
    "build",
    "build_compare",
    "route_params",
    "select",
]

DEFAULT_DETECTOR = "conspicuity"
STAGES = ("detector", "verifier", "classifier", "tracker")

Params = Sequence[str] | Mapping[str, Any]
Config = str | os.PathLike | Mapping[str, Any] | None


@dataclass(frozen=True)
class Selection:
    """The plugins of one run, built and validated."""

    detector: Detector | None = None
    verifier: Verifier | None = None
    classifier: Classifier | None = None
    tracker: Tracker | None = None

    def pipeline(self) -> Pipeline:
        """The detector -> verifier -> tracker -> classifier pipeline of these plugins."""
        if self.detector is None:
            raise ParamError("a pipeline needs a detector")
        return Pipeline(self.detector, self.classifier, self.tracker, self.verifier)


def build(
    detector: str | None = None,
    verifier: str | None = None,
    classifier: str | None = None,
    tracker: str | None = None,
    params: Params = (),
    config: Config = None,
    classifier_alone: bool = False,
    with_tracker: bool = True,
) -> Selection:
    """Instantiate the chosen plugins with validated, routed parameters.

    Parameters
    ----------
    detector, verifier, classifier, tracker : str, optional
        Plugin names; a name in ``config`` (``{kind: {"name", "params"}}``) fills a gap.
    params : sequence of ``"key=value"`` or mapping
        A key may be prefixed with the plugin kind (``classifier.model``); an unprefixed key
        goes to the one chosen plugin that declares it. They override the config's params.
    config : path or mapping, optional
        A YAML run configuration (:func:`tsrkit.plugin.params.load_config`) or its content.
    classifier_alone : bool
        When a classifier and no detector is named, run the classifier alone (on ground-truth
        boxes) instead of adding the default detector.
    with_tracker : bool
        False for a run that evaluates frames independently: a config naming a tracker is then
        refused rather than ignored.
    """
    settings = _config(config)
    if not with_tracker:
        no_tracker(settings)
    chosen = {}
    for kind, given in zip(STAGES, (detector, verifier, classifier, tracker)):
        name = given or (settings.get(kind) or {}).get("name")
        if name:
            chosen[kind] = name
    if "detector" not in chosen and not (classifier_alone and "classifier" in chosen):
        chosen["detector"] = DEFAULT_DETECTOR
    registry = get_registry()
    for kind, name in chosen.items():
        registry.get(kind, name)  # a clear error for an unknown name before routing params
    routed = route_params(chosen, _assignments(params), settings)
    return Selection(
        **{
            kind: registry.create(kind, name, routed[kind])  # type: ignore[arg-type]
            for kind, name in chosen.items()
        }
    )


#: ``tsrkit.select``: the library's name for :func:`build`.
select = build


def build_compare(
    detectors: Sequence[str],
    classifier: str | None = None,
    verifier: str | None = None,
    params: Params = (),
    config: Config = None,
) -> list[Selection]:
    """One :class:`Selection` per detector, sharing the classifier and verifier.

    A key prefixed with a detector's name (``conspicuity.weights``) goes to that detector, one
    prefixed with a kind (``classifier.model``, ``detector.roi``) to that stage; an unprefixed
    key to every chosen plugin that declares it. A key no chosen plugin declares is refused.
    ``config`` (a run configuration or preset) names the verifier and classifier when the
    arguments do not, and gives its plugins' params (its detector's to that detector, if
    compared); ``params`` override them.
    """
    settings = _config(config)
    no_tracker(settings)
    verifier = verifier or (settings.get("verifier") or {}).get("name")
    classifier = classifier or (settings.get("classifier") or {}).get("name")
    assignments: dict[str, Any] = {}
    for kind, name in (("verifier", verifier), ("classifier", classifier)):
        entry = settings.get(kind) or {}
        if name and entry.get("name") == name:
            assignments.update({f"{kind}.{k}": v for k, v in entry.get("params", {}).items()})
    entry = settings.get("detector") or {}
    if entry.get("name") in detectors:
        assignments.update({f"{entry['name']}.{k}": v for k, v in entry["params"].items()})
    assignments.update(_assignments(params))
    registry = get_registry()
    shared = {
        kind: name for kind, name in (("verifier", verifier), ("classifier", classifier)) if name
    }
    for kind, name in [*(("detector", d) for d in detectors), *shared.items()]:
        registry.get(kind, name)
    declared = {
        (kind, name): {p.name for p in registry.get(kind, name).cls.PARAMS}
        for kind, name in [*(("detector", d) for d in detectors), *shared.items()]
    }
    per_run: list[dict[str, dict[str, Any]]] = [
        {kind: {} for kind in ("detector", *shared)} for _ in detectors
    ]
    for key, value in assignments.items():
        prefix, dot, bare = key.partition(".")
        if dot and (prefix in detectors or prefix in ("detector", *shared)):
            targets = [
                (i, "detector") for i, d in enumerate(detectors) if prefix in (d, "detector")
            ] or [(i, prefix) for i in range(len(detectors))]
        else:
            bare = key
            targets = [
                (i, kind)
                for i, d in enumerate(detectors)
                for kind, name in (("detector", d), *shared.items())
                if bare in declared[(kind, name)]
            ]
            if not targets:
                names = ", ".join([*detectors, *shared.values()])
                raise ParamError(
                    f"unknown parameter '{key}': none of {names} declares it "
                    "(prefix it with a detector name or with classifier. / "
                    "verifier.)"
                )
        for i, kind in targets:
            per_run[i][kind][bare] = value
    return [
        Selection(
            detector=registry.create("detector", d, per_run[i]["detector"]),
            **{
                kind: registry.create(kind, name, per_run[i][kind])  # type: ignore[arg-type]
                for kind, name in shared.items()
            },
        )
        for i, d in enumerate(detectors)
    ]


def no_tracker(settings: Mapping[str, Any]) -> None:
    """Refuse a run configuration that names a tracker where frames are evaluated one by one
    (``benchmark``, ``compare``): it would be ignored without a word."""
    entry = settings.get("tracker")
    if entry:
        raise ParamError(
            f"the config names tracker '{entry['name']}', but this verb evaluates frames one by "
            "one and runs no tracker (use it with detect or track)"
        )


def route_params(
    selected: Mapping[str, str],
    assignments: Mapping[str, Any],
    config: Mapping[str, Any] | None = None,
) -> dict[str, dict[str, Any]]:
    """Give each ``key: value`` to the selected plugin that declares ``key``.

    A key may be prefixed with the plugin kind (``classifier.model``) or with the selected
    plugin's name (``onnx-detector.model``, as ``compare`` takes it); an unprefixed key goes to
    the only selected plugin that declares it. Config params come first (only for the plugin
    the config names); ``assignments`` override them.
    """
    registry = get_registry()
    routed: dict[str, dict[str, Any]] = {kind: {} for kind in selected}
    for kind, name in selected.items():
        entry = (config or {}).get(kind) or {}
        if entry.get("name") in (None, name):  # a plugin named instead drops the config's params
            routed[kind].update(entry.get("params", {}))
    for key, value in assignments.items():
        kind, dot, bare = key.partition(".")
        if dot and kind in selected:
            routed[kind][bare] = value
            continue
        named = [k for k, name in selected.items() if name == kind]
        if dot and len(named) > 1:
            raise ParamError(
                f"parameter '{key}': '{kind}' is selected as {' and '.join(named)}; "
                f"write {named[0]}.{bare}=..."
            )
        if dot and named:
            routed[named[0]][bare] = value
            continue
        owners = [
            k
            for k, name in selected.items()
            if key in {p.name for p in registry.get(k, name).cls.PARAMS}
        ]
        if len(owners) == 1:
            routed[owners[0]][key] = value
        elif owners:
            raise ParamError(
                f"parameter '{key}' is declared by both {' and '.join(owners)}; "
                f"write {owners[0]}.{key}=..."
            )
        else:
            names = " or ".join(f"{k} '{n}'" for k, n in selected.items())
            allowed = sorted(
                {p.name for k, n in selected.items() for p in registry.get(k, n).cls.PARAMS}
            )
            raise ParamError(
                f"{names}: unknown parameter '{key}' (allowed: {', '.join(allowed) or 'none'})"
            )
    return routed


def _assignments(params: Params) -> dict[str, Any]:
    return dict(params) if isinstance(params, Mapping) else parse_assignments(params)


def _config(config: Config) -> Mapping[str, Any]:
    if config is None:
        return {}
    return config if isinstance(config, Mapping) else load_config(config)
