"""The fast radial symmetry transform (Loy & Zelinsky 2003) and the Lab-FRST detector built on it.

Building block for plugin authors: ``from tsrkit_plugins.detectors.frst import frst`` gives the
transform of any 2-D float map (``frst.py``); ``lab_frst.py`` is Siogkas et al.'s detector
(Zheng 5.2.2) that runs it on the L*(a+b) map.
"""

from tsrkit_plugins.detectors.frst.frst import (
    cast_votes,
    frst,
    kappa,
    orientation_strength,
    radial_strength,
    select_voters,
    sobel_gradient,
)

__all__ = [
    "cast_votes",
    "frst",
    "kappa",
    "orientation_strength",
    "radial_strength",
    "select_voters",
    "sobel_gradient",
]
