"""The ONNX Runtime session of a detection model, opened with one clear line for a bad file.

One intra-op thread and the CPU provider: the engine's worker processes give the parallelism
(``/work/shared/DESIGN.md``, "Learned stages"). ONNX Runtime is imported here, when a model is
first opened, so loading the plugin costs nothing.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tsrkit.api import ModelError
from tsrkit_plugins.detectors.onnx_detector.layouts import OutputInfo

#: ONNX Runtime's element types and the NumPy dtypes fed to them: the image's, and a size
#: input's (RT-DETR's ``orig_target_sizes``).
INPUT_DTYPES = {"tensor(float)": np.float32, "tensor(float16)": np.float16}
SIZE_DTYPES = {"tensor(int64)": np.int64, "tensor(int32)": np.int32, "tensor(float)": np.float32}


@dataclass(frozen=True)
class Session:
    """An open model: the runtime session and what the plugin reads from its signature.

    Parameters
    ----------
    runtime : onnxruntime.InferenceSession
        The session (never pickled: the plugin drops it when it is sent to a worker).
    input_name : str
        The image input.
    input_dtype : type
        Its NumPy element type.
    size_inputs : tuple of (str, type)
        Inputs fed the input's ``[[width, height]]`` (RT-DETR's ``orig_target_sizes``, to
        which its boxes are scaled), with their element types.
    size : tuple of int or None
        ``(H, W)`` of the input, or None where a dimension is dynamic.
    outputs : tuple of OutputInfo
        The outputs, in the model's order.
    metadata : dict
        The model's ``metadata_props`` (Ultralytics writes ``names``, ``imgsz``...).
    """

    runtime: Any
    input_name: str
    input_dtype: type
    size_inputs: tuple[tuple[str, type], ...]
    size: tuple[int, int] | None
    outputs: tuple[OutputInfo, ...]
    metadata: dict[str, str]

    def run(self, tensor: np.ndarray) -> list[np.ndarray]:
        """The outputs for one ``(1, 3, H, W)`` input."""
        feeds: dict[str, np.ndarray] = {self.input_name: tensor.astype(self.input_dtype)}
        for name, dtype in self.size_inputs:
            feeds[name] = np.array([[tensor.shape[3], tensor.shape[2]]], dtype)
        return self.runtime.run(None, feeds)


def open_session(path: Path) -> Session:
    """Open the model at ``path`` on the CPU with one intra-op thread.

    Raises
    ------
    ModelError
        When the file is missing or not an ONNX model ONNX Runtime can run, or when its
        inputs are not one float image ``[N, 3, H, W]``, first, and optionally sizes ``[N,
        2]`` (an input whose name holds ``size``).
    """
    if not path.is_file():
        raise ModelError(f"{path}: no such file (the ONNX model)")
    import onnxruntime as ort

    options = ort.SessionOptions()
    options.intra_op_num_threads = 1
    options.inter_op_num_threads = 1
    options.log_severity_level = 3  # errors only: the plugin words its own
    try:
        runtime = ort.InferenceSession(
            str(path), sess_options=options, providers=["CPUExecutionProvider"]
        )
    except Exception as exc:  # ONNX Runtime raises its own Fail/InvalidProtobuf/... classes
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ModelError(f"{path}: not an ONNX model ONNX Runtime can run ({reason})") from None
    first, *extra = runtime.get_inputs()
    sizes = [
        (i.name, SIZE_DTYPES[i.type])
        for i in extra
        if "size" in i.name.lower() and i.type in SIZE_DTYPES and tuple(i.shape)[-1:] == (2,)
    ]
    if len(sizes) != len(extra):
        names = ", ".join(i.name for i in (first, *extra))
        raise ModelError(
            f"{path}: the model's inputs are {names}; expected an image, optionally followed "
            "by sizes [1, 2]"
        )
    shape = tuple(first.shape)
    if len(shape) != 4 or shape[1] != 3 or first.type not in INPUT_DTYPES:
        raise ModelError(
            f"{path}: input '{first.name}' is {first.type} {list(shape)}; expected a float "
            "image [1, 3, height, width]"
        )
    height, width = shape[2:]
    size = (height, width) if isinstance(height, int) and isinstance(width, int) else None
    meta = runtime.get_modelmeta().custom_metadata_map
    return Session(
        runtime,
        first.name,
        INPUT_DTYPES[first.type],
        tuple(sizes),
        size,
        tuple(OutputInfo(o.name, tuple(o.shape), o.type) for o in runtime.get_outputs()),
        dict(meta),
    )
