"""Signal nodes of an OpenStreetMap ``.pbf`` extract through pyosmium (optional: ``pip install
osmium``); Zheng 2016, 4.4."""

from __future__ import annotations

from pathlib import Path

from tsrkit.geo.errors import GeoError

__all__ = ["SIGNAL_TAGS", "pbf_nodes"]

#: The tags that make a node a signal (``highway``) or a pedestrian signal (``crossing``).
SIGNAL_TAGS = (("highway", "traffic_signals"), ("crossing", "traffic_signals"))


def pbf_nodes(path: Path) -> list[tuple[int, float, float, dict[str, str], str]]:
    """``(id, lat, lon, tags, label)`` of the signal nodes, read by libosmium's own PBF reader
    with a tag filter (the other objects are skipped without being built in Python).

    Raises
    ------
    GeoError
        pyosmium missing, a missing or malformed file, a signal node without a location.
    """
    try:
        # osmium is optional (extra "pbf"): only for .osm.pbf maps
        import osmium
        import osmium.filter
    except ImportError:
        raise GeoError(path, "reading .pbf needs pyosmium (pip install osmium)") from None
    if not path.is_file():
        raise GeoError(path, "no such file")
    nodes = []
    try:
        processor = osmium.FileProcessor(str(path), osmium.osm.NODE).with_filter(
            osmium.filter.TagFilter(*SIGNAL_TAGS)
        )
        for node in processor:
            if not isinstance(node, osmium.osm.Node):  # the processor reads nodes only
                continue
            label = f"node {node.id}"
            if not node.location.valid():
                raise GeoError(path, "signal node without a valid location", label)
            nodes.append((node.id, node.location.lat, node.location.lon, dict(node.tags), label))
    except RuntimeError as exc:
        raise GeoError(path, f"not a readable OSM PBF file ({exc})") from None
    return nodes
