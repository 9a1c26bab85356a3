"""tsrkit: traffic signal recognition with interchangeable, benchmarked methods.

Everything the command line does is a plain call here first::

    import tsrkit
    det = tsrkit.detector("conspicuity", weights=(1, 1, 2))
    cls = tsrkit.classifier("ab-hist")
    frame = tsrkit.read_frame("frame.png")
    detections = cls.classify(frame, det.detect(frame))

It is also the whole plugin API: ``from tsrkit import hookimpl, Detector, Param, Candidate``
(and the other public names of ``__init__.pyi``) is all a plugin module needs to import.
"""

import lazy_loader as _lazy

from tsrkit._rooms import ROOMS as _ROOMS

# Every public name is imported on first use (PEP 562), so that ``import tsrkit`` (and
# ``tsrkit --help``) does not load NumPy, OpenCV or the plugins; the names and where they live
# are listed once, in ``__init__.pyi``, which type checkers read too.
__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)
# ``from tsrkit import *`` takes the public names, not the rooms (each one attribute away).
__all__ = [n for n in __all__ if n != "__version__" and not any(n in f for f in _ROOMS)]
