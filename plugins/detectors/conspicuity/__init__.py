"""Zheng's conspicuity detector (Zheng 2016, 3.2.1-3.2.2): the map, its kernels, the plugin.

``conspicuity.py`` holds the map (Eq. 3.1-3.12) and the plugin, ``conspicuity_kernel.py`` the
compiled window sums, ``colour.py`` the one-pass L and S, ``workspace.py`` the per-thread
scratch arrays; the localization of 3.2.2 is shared with gray-tophat
(:mod:`tsrkit_plugins.detectors.localization`).
"""

from tsrkit_plugins.detectors.conspicuity.conspicuity import (
    Conspicuity,
    conspicuity_map,
    lightness,
    register_detectors,
    saturation,
)

__all__ = ["Conspicuity", "conspicuity_map", "lightness", "register_detectors", "saturation"]
