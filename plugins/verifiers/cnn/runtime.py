"""The network at run time: an ONNX Runtime session, one intra-op thread (worker processes
give the parallelism), and the card that says what the model is."""

from __future__ import annotations

from typing import Any

from tsrkit.api import ModelError

#: The input and outputs a model of this plugin has (name: rank).
INPUTS = {"crops": 4}
OUTPUTS = {"light": 1, "box": 2, "state": 2}


def session(model: bytes, where: str) -> Any:
    """An ONNX Runtime session of the ``model`` bytes, checked for the plugin's input and
    outputs.

    Raises
    ------
    ModelError
        Not an ONNX model ONNX Runtime can run, or not this plugin's inputs and outputs.
    """
    import onnxruntime

    options = onnxruntime.SessionOptions()
    options.intra_op_num_threads = 1
    options.inter_op_num_threads = 1
    options.log_severity_level = 3
    try:
        runtime = onnxruntime.InferenceSession(model, options, providers=["CPUExecutionProvider"])
    except Exception as exc:  # ONNX Runtime raises its own exception types for bad files
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ModelError(
            f"model {where}: not an ONNX model ONNX Runtime can run ({first})"
        ) from None
    inputs = {i.name: len(i.shape) for i in runtime.get_inputs()}
    outputs = {o.name: len(o.shape) for o in runtime.get_outputs()}
    if inputs != INPUTS or outputs != OUTPUTS:
        raise ModelError(
            f"model {where}: inputs {inputs} and outputs {outputs} are not a cnn-verifier "
            f"model's ({INPUTS}, {OUTPUTS})"
        )
    return runtime
