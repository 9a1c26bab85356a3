"""A local conformal projection (Zheng 2016, 3.4.1): transverse Mercator centred on the data,
through pyproj, so that distances and angles in metres hold over a city."""

from __future__ import annotations

import numpy as np
from pyproj import Transformer

__all__ = ["LocalProjection"]


class LocalProjection:
    """Latitude / longitude to metres east / north of ``(lat0, lon0)``."""

    def __init__(self, lat0: float, lon0: float):
        self.lat0, self.lon0 = float(lat0), float(lon0)
        self._forward = Transformer.from_crs(
            "EPSG:4326",
            f"+proj=tmerc +lat_0={lat0} +lon_0={lon0} +k=1 +x_0=0 +y_0=0 +ellps=WGS84 +units=m",
            always_xy=True,
        )

    def __call__(self, lat, lon) -> tuple[np.ndarray, np.ndarray]:
        x, y = self._forward.transform(np.asarray(lon, np.float64), np.asarray(lat, np.float64))
        return np.asarray(x), np.asarray(y)
