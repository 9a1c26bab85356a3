"""Signalised intersections from an OpenStreetMap extract (Zheng 2016, 4.4).

``highway=traffic_signals`` nodes are intersection signals; ``crossing=traffic_signals`` nodes
(pedestrian crossings) are kept apart. Signal nodes within :data:`MERGE_M` metres of each other
(one per approach on many junctions) are merged into one intersection at their centroid.
"""

from __future__ import annotations

import gzip
import math
import os
import zlib
from dataclasses import dataclass
from pathlib import Path
from xml.etree.ElementTree import ParseError

import numpy as np
from defusedxml import DefusedXmlException, ElementTree
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from tsrkit.geo.errors import GeoError, check_file, read_text
from tsrkit.geo.geojson import geojson_nodes
from tsrkit.geo.osm_pbf import SIGNAL_TAGS, pbf_nodes
from tsrkit.geo.projection import LocalProjection

__all__ = ["MAP_FORMATS", "MERGE_M", "Signals", "map_format", "read_signals"]

#: Signal nodes closer than this (metres) belong to one intersection.
MERGE_M = 50.0


@dataclass(frozen=True)
class Signals:
    """Intersections (merged ``highway=traffic_signals`` nodes) and pedestrian signals.

    ``ids`` are the OSM ids of each intersection's nodes; ``lat``, ``lon`` its centroid.
    """

    source: str
    ids: tuple[tuple[int, ...], ...]
    lat: np.ndarray
    lon: np.ndarray
    crossing_lat: np.ndarray
    crossing_lon: np.ndarray

    def __len__(self) -> int:
        return len(self.ids)


def _xml_nodes(path: Path) -> list[tuple[int, float, float, dict[str, str], str]]:
    opener = gzip.open if path.suffix == ".gz" else open
    try:
        with opener(path, "rb") as fh:
            root = ElementTree.parse(fh).getroot()
    except FileNotFoundError:
        raise GeoError(path, "no such file") from None
    except ParseError as exc:
        raise GeoError(path, f"not well-formed XML ({exc})", exc.position[0]) from None
    except DefusedXmlException as exc:
        raise GeoError(path, f"refused XML ({type(exc).__name__})") from None
    except LookupError as exc:  # the XML declaration names an unknown encoding
        raise GeoError(path, f"cannot decode the XML ({exc})") from None
    except (OSError, EOFError, zlib.error) as exc:
        raise GeoError(path, f"cannot read ({exc})") from None
    nodes = []
    for node in root.iter("node"):
        tags = {t.get("k", ""): t.get("v", "") for t in node.iter("tag")}
        if not any(tags.get(key) == value for key, value in SIGNAL_TAGS):
            continue
        try:
            ident, lat, lon = (
                int(node.get("id", "")),
                float(node.get("lat", "")),
                float(node.get("lon", "")),
            )
        except ValueError:
            raise GeoError(
                path, f"node {node.get('id')!r}: id, lat or lon is not a number"
            ) from None
        nodes.append((ident, lat, lon, tags, f"node {ident}"))
    return nodes


#: Every format :func:`map_format` answers (``tsrkit track --map`` names each in its help).
MAP_FORMATS = ("xml", "pbf", "geojson")


def map_format(path: Path) -> str:
    """``pbf``, ``geojson`` or ``xml`` (``.osm``, ``.osm.gz`` and any other name), by extension.

    >>> map_format(Path("bellevue.osm.pbf")), map_format(Path("signals.geojson"))
    ('pbf', 'geojson')
    """
    suffix = path.suffix.lower()
    return "pbf" if suffix == ".pbf" else "geojson" if suffix in (".geojson", ".json") else "xml"


def _nodes(path: Path) -> list[tuple[int, float, float, dict[str, str]]]:
    """``(id, lat, lon, tags)`` of the signal nodes of a map in any :func:`map_format`, with
    finite coordinates in range."""
    kind = map_format(path)
    if kind == "pbf":
        found = pbf_nodes(path)
    elif kind == "geojson":
        found = geojson_nodes(path, read_text(path))
    else:
        found = _xml_nodes(path)
    for _, lat, lon, _, label in found:
        if not (math.isfinite(lat) and math.isfinite(lon)):
            raise GeoError(path, f"lat {lat} / lon {lon} not finite", label)
        if not (-90 <= lat <= 90 and -180 <= lon <= 180):
            raise GeoError(path, f"lat {lat} / lon {lon} out of range", label)
    return [n[:4] for n in found]


def read_signals(path: str | os.PathLike, merge_m: float = MERGE_M) -> Signals:
    """Read the signals of an ``.osm`` or ``.osm.gz`` extract (XML parsed with defusedxml), an
    ``.osm.pbf`` extract (through pyosmium, when installed) or a GeoJSON file of signal points.

    Raises
    ------
    GeoError
        Missing file, malformed XML or JSON (with its line), a malformed PBF file, or a signal
        node (feature) with bad coordinates.
    """
    path = Path(path)
    if path.exists():  # a missing file is each reader's own message
        check_file(path)
    nodes = _nodes(path)
    signals = [n for n in nodes if n[3].get("highway") == "traffic_signals"]
    crossings = [n for n in nodes if n[3].get("highway") != "traffic_signals"]
    if not signals:
        empty = np.zeros(0)
        return Signals(
            str(path),
            (),
            empty,
            empty,
            np.array([n[1] for n in crossings]),
            np.array([n[2] for n in crossings]),
        )
    lat = np.array([n[1] for n in signals])
    lon = np.array([n[2] for n in signals])
    x, y = LocalProjection(lat.mean(), lon.mean())(lat, lon)
    pairs = cKDTree(np.column_stack([x, y])).query_pairs(merge_m, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(lat),) * 2)
    count, label = connected_components(graph, directed=False)
    ids = tuple(tuple(signals[i][0] for i in np.flatnonzero(label == k)) for k in range(count))
    return Signals(
        str(path),
        ids,
        np.array([lat[label == k].mean() for k in range(count)]),
        np.array([lon[label == k].mean() for k in range(count)]),
        np.array([n[1] for n in crossings]),
        np.array([n[2] for n in crossings]),
    )
