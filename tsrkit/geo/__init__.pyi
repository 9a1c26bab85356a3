from tsrkit.geo.errors import GeoError as GeoError
from tsrkit.geo.gps import Track as Track, read_track as read_track
from tsrkit.geo.osm import Signals as Signals, read_signals as read_signals
from tsrkit.geo.projection import LocalProjection as LocalProjection
from tsrkit.geo.vicinity import (
    Traversal as Traversal,
    movement as movement,
    traversals as traversals,
)
