"""Solar geometry against pvlib: the largest azimuth and elevation errors of Lee's equations
(2017, 4.1.1) and of the NOAA algorithm tsrkit runs, over 2025 every 7 minutes at seven
latitudes of both hemispheres (Sun above the horizon; azimuth below 88 degrees of elevation),
and the time each takes for one year of positions.

Run from the repository root: ``python benchmarks/sun_geometry.py`` (needs pvlib and pandas,
which the test extra installs).
"""

from __future__ import annotations

import argparse
import time

import harness
import numpy as np
import pandas as pd
from pvlib import solarposition

from tsrkit.sun.geometry import sun_position, sun_position_lee

PLACES = [("Ushuaia", -54.8, -68.3), ("Sydney", -33.9, 151.2), ("Kampala", 0.3, 32.6),
          ("Havana", 23.1, -82.4), ("Pittsburgh", 40.4, -80.0), ("Berlin", 52.5, 13.4),
          ("Reykjavik", 64.1, -21.9)]  # fmt: skip


def timed(function, *args, **kwargs):
    start = time.perf_counter()
    result = function(*args, **kwargs)
    return result, time.perf_counter() - start


def main() -> None:
    argparse.ArgumentParser(description=__doc__).parse_args()  # --help only
    harness.announce()
    times = pd.date_range("2025-01-01", "2026-01-01", freq="7min", tz="UTC")[:-1]
    utc = (times - pd.Timestamp("1970-01-01", tz="UTC")).total_seconds().to_numpy()
    print(f"{len(times)} instants per place")
    print(
        f"{'place':11s} {'lat':>6s}  {'NOAA el':>8s} {'NOAA az':>8s}  {'Lee el':>7s} {'Lee az':>7s}"
    )
    seconds = {"pvlib": 0.0, "noaa": 0.0, "lee": 0.0}
    for name, lat, lon in PLACES:
        ref, dt = timed(solarposition.get_solarposition, times, lat, lon, method="nrel_numpy")
        seconds["pvlib"] += dt
        ref_az, ref_el = ref["azimuth"].to_numpy(), ref["elevation"].to_numpy()
        up, steep = ref_el > 0, (ref_el > 0) & (ref_el < 88)
        row = []
        for key, position in (("noaa", sun_position), ("lee", sun_position_lee)):
            (az, el), dt = timed(position, utc, lat, lon)
            seconds[key] += dt
            row += [
                np.abs(el - ref_el)[up].max(),
                np.abs((az - ref_az + 180) % 360 - 180)[steep].max(),
            ]
        print(f"{name:11s} {lat:6.1f}  {row[0]:8.3f} {row[1]:8.3f}  {row[2]:7.3f} {row[3]:7.3f}")
    per = {k: 1e6 * v / (len(times) * len(PLACES)) for k, v in seconds.items()}
    print("microseconds per position: " + ", ".join(f"{k} {v:.3f}" for k, v in per.items()))
    print(f"NOAA is {per['pvlib'] / per['noaa']:.1f}x faster than pvlib's nrel_numpy")


if __name__ == "__main__":
    main()
