"""``onnx-detector``: run your own ONNX detection model beside the paper methods.

Beyond the documents. A model exported from Ultralytics (``yolo export format=onnx``) or any
post-NMS detection graph runs through ONNX Runtime on the CPU with one intra-op thread (the
engine's workers give the parallelism), created on first use in each process and never
pickled. The modules, one job each:

- ``letterbox.py``: Ultralytics' letterbox (grey 114, RGB, /255, NCHW float32), its exact
  inverse for the boxes, and the tiles of a large frame (``tile``: overlapping tiles plus the
  whole frame, merged by class-aware NMS, for small lights);
- ``layouts.py``: the two output layouts (``yolo``: ``[1, 4+nc, anchors]`` or its transpose,
  confidence filter and class-aware NMS; ``boxes``: boxes, scores and labels after NMS), told
  apart by ``layout=auto`` from the output names and shapes;
- ``names.py``: the class names (``names=``, ``MODEL.yaml``/``MODEL.json`` beside the model,
  or the Ultralytics metadata) and the state a name says;
- ``session.py``: the ONNX Runtime session and its checks;
- ``plugin.py``: the detector.

A bad model stops the run with one line (:class:`tsrkit.api.ModelError`): a missing file, a
file that is not ONNX, an input that is not one float image ``[1, 3, H, W]``, outputs neither
layout reads, class names that do not match the model's classes. Boxes with a value that is not
finite (NaN, infinity) are left out, and the frame's record notes how many.
"""

from tsrkit_plugins.detectors.onnx_detector.plugin import OnnxDetector, register_detectors

__all__ = ["OnnxDetector", "register_detectors"]
