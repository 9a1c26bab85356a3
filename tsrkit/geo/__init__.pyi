from .errors import GeoError as GeoError
from .gps import Track as Track, read_track as read_track
from .osm import Signals as Signals, read_signals as read_signals
from .projection import LocalProjection as LocalProjection
from .vicinity import (
    Traversal as Traversal,
    movement as movement,
    traversals as traversals,
)
