"""Where the car is: GPS tracks, signal maps and the vicinity profile of Zheng's spatiotemporal
framework (2016, 3.4.1-3.4.3, 4.3-4.4).

``read_track`` reads a GPS log (CSV, whitespace lines, GPX, NMEA), ``read_signals`` the
signalised intersections of an OpenStreetMap extract (``.osm``, ``.osm.gz``, ``.osm.pbf``) or
GeoJSON points, ``traversals`` finds the passes of the track through them with their movement;
:mod:`tsrkit.geo.nearest` holds the basic and Zheng's extended k-d tree searches. No network is
used: the map is a local extract (cut one with ``osmium extract``).

Names are imported on first use (PEP 562, declared in ``__init__.pyi``): reading a GPS log
does not import the map reader's SciPy graph routines.
"""

import lazy_loader as _lazy

__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)
