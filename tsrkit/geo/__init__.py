"""Where the car is: GPS tracks, signal maps and the vicinity profile of Zheng's spatiotemporal
framework (2016, 3.4.1-3.4.3, 4.3-4.4).

``read_track`` reads a GPS log (CSV, whitespace lines, GPX, NMEA), ``read_signals`` the
signalised intersections of an OpenStreetMap extract (``.osm``, ``.osm.gz``, ``.osm.pbf``) or
GeoJSON points, ``traversals`` finds the passes of the track through them with their movement;
:mod:`tsrkit.geo.nearest` holds the basic and Zheng's extended k-d tree searches. No network is
used: the map is a local extract (cut one with ``osmium extract``).
"""

from tsrkit.geo.errors import GeoError
from tsrkit.geo.gps import Track, read_track
from tsrkit.geo.osm import Signals, read_signals
from tsrkit.geo.projection import LocalProjection
from tsrkit.geo.vicinity import Traversal, movement, traversals

__all__ = [
    "GeoError",
    "LocalProjection",
    "Signals",
    "Track",
    "Traversal",
    "movement",
    "read_signals",
    "read_track",
    "traversals",
]
