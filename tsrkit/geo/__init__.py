"""Where the car is: GPS tracks, signal maps and the vicinity profile of Zheng's spatiotemporal
framework (2016, 3.4.1-3.4.3, 4.3-4.4).

``read_track`` reads a GPS log, ``read_signals`` the signalised intersections of an
OpenStreetMap extract, ``traversals`` finds the passes of the track through them with their
movement. No network is used: the map is a local extract (cut one with ``osmium extract``).
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
