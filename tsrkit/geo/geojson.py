"""Signal points of a GeoJSON file, e.g. an Overpass export (Zheng 2016, 4.4)."""

from __future__ import annotations

import json
import re
from pathlib import Path

from tsrkit.geo.errors import GeoError
from tsrkit.geo.osm_pbf import SIGNAL_TAGS

__all__ = ["geojson_nodes"]

_NODE_ID = re.compile(r"(?:node/)?(\d+)")


def _ident(feature: dict, number: int) -> int:
    """The OSM node id of a feature (``id`` or the ``@id`` / ``id`` / ``osm_id`` property, as
    ``123`` or ``"node/123"``), else its number in the file."""
    properties = feature.get("properties") or {}
    for value in (
        feature.get("id"),
        properties.get("@id"),
        properties.get("id"),
        properties.get("osm_id"),
    ):
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        match = _NODE_ID.fullmatch(value) if isinstance(value, str) else None
        if match:
            return int(match.group(1))
    return number


def geojson_nodes(path: Path, text: str) -> list[tuple[int, float, float, dict[str, str], str]]:
    """``(id, lat, lon, tags, label)`` of the features whose properties hold
    ``highway=traffic_signals`` or ``crossing=traffic_signals``; the label is "feature N", N
    counting from 1. A FeatureCollection or a single Feature.

    Raises
    ------
    GeoError
        Invalid JSON (with its line), not GeoJSON features, a signal feature that is not a
        Point or whose coordinates are not two or three numbers.
    """
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise GeoError(path, f"not JSON ({exc.msg})", exc.lineno) from None
    except (RecursionError, ValueError) as exc:
        raise GeoError(path, f"not JSON ({type(exc).__name__}: {exc})") from None
    if isinstance(data, dict) and data.get("type") == "Feature":
        data = {"type": "FeatureCollection", "features": [data]}
    if not isinstance(data, dict) or not isinstance(data.get("features"), list):
        raise GeoError(path, "not a GeoJSON FeatureCollection or Feature")
    nodes = []
    for number, feature in enumerate(data["features"], start=1):
        label = f"feature {number}"
        if not isinstance(feature, dict) or not isinstance(feature.get("properties") or {}, dict):
            raise GeoError(path, "not a GeoJSON feature with a properties object", label)
        tags = {str(k): str(v) for k, v in (feature.get("properties") or {}).items()}
        if not any(tags.get(key) == value for key, value in SIGNAL_TAGS):
            continue
        geometry = feature.get("geometry")
        kind = geometry.get("type") if isinstance(geometry, dict) else None
        if kind != "Point":
            raise GeoError(path, f"a traffic_signals feature must be a Point, not {kind}", label)
        coordinates = geometry.get("coordinates") if isinstance(geometry, dict) else None
        if (
            not isinstance(coordinates, list)
            or len(coordinates) not in (2, 3)
            or not all(isinstance(c, int | float) and not isinstance(c, bool) for c in coordinates)
        ):
            raise GeoError(path, "Point coordinates must be [lon, lat] numbers", label)
        try:
            lon, lat = float(coordinates[0]), float(coordinates[1])
        except OverflowError:
            raise GeoError(path, "Point coordinates out of range", label) from None
        nodes.append((_ident(feature, number), lat, lon, tags, label))
    return nodes
