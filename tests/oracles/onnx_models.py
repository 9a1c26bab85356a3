"""Tiny ONNX detection models built by hand with ``onnx.helper``, whose outputs are known.

- :func:`constant_model`: outputs fixed tensors whatever the image (exact box maths);
- :func:`brightest_model`: a ``boxes``-layout model that finds the brightest pixel of the
  input's first (red) channel, a 5 x 5 box centred on it, scored by that pixel's value (tiling
  and end-to-end runs, where the answer must depend on the image);
- :func:`rtdetr_model`: boxes scaled by a second input, the sizes, as RT-DETR's deploy
  export does.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

OPSET = [helper.make_opsetid("", 17)]


def _image_input(size: tuple[int | str, int | str]) -> onnx.ValueInfoProto:
    return helper.make_tensor_value_info("images", TensorProto.FLOAT, [1, 3, *size])


def _save(graph: onnx.GraphProto, path: Path, metadata: Mapping[str, str] | None) -> Path:
    model = helper.make_model(graph, opset_imports=OPSET)
    model.ir_version = 8
    for key, value in (metadata or {}).items():
        entry = model.metadata_props.add()
        entry.key, entry.value = key, value
    onnx.checker.check_model(model)
    onnx.save(model, str(path))
    return path


def constant_model(
    path: Path,
    outputs: Mapping[str, np.ndarray],
    size: tuple[int | str, int | str] = (64, 64),
    metadata: Mapping[str, str] | None = None,
) -> Path:
    """A model with one image input of ``size`` whose outputs are the given arrays (by name,
    in order), each a Constant node."""
    nodes, infos = [], []
    for name, value in outputs.items():
        tensor = numpy_helper.from_array(np.asarray(value), name=f"{name}_value")
        nodes.append(helper.make_node("Constant", [], [name], value=tensor))
        elem = helper.np_dtype_to_tensor_dtype(np.asarray(value).dtype)
        infos.append(helper.make_tensor_value_info(name, elem, list(np.shape(value))))
    graph = helper.make_graph(nodes, "constant", [_image_input(size)], infos)
    return _save(graph, path, metadata)


def yolo_output(
    boxes: list[tuple[float, float, float, float, int, float]], classes: int, anchors: int = 8
) -> np.ndarray:
    """An Ultralytics ``[1, 4 + classes, anchors]`` output holding ``(cx, cy, w, h, class,
    score)`` in its first anchors, zeros elsewhere."""
    out = np.zeros((1, 4 + classes, anchors), np.float32)
    for i, (cx, cy, w, h, label, score) in enumerate(boxes):
        out[0, :4, i] = cx, cy, w, h
        out[0, 4 + label, i] = score
    return out


def brightest_model(path: Path, size: tuple[int, int] = (100, 100)) -> Path:
    """The ``boxes``-layout model described in the module docstring (label 0)."""
    height, width = size

    def const(name: str, value) -> onnx.NodeProto:
        return helper.make_node(
            "Constant", [], [name], value=numpy_helper.from_array(np.asarray(value), name)
        )

    nodes = [
        const("starts", np.array([0], np.int64)),
        const("ends", np.array([1], np.int64)),
        const("axis1", np.array([1], np.int64)),
        const("flat_shape", np.array([1, height * width], np.int64)),
        const("width", np.array([[width]], np.int64)),
        const("lo", np.array([[-2.0]], np.float32)),
        const("hi", np.array([[3.0]], np.float32)),
        const("labels", np.array([0], np.int64)),
        const("score_shape", np.array([1], np.int64)),
        helper.make_node("Slice", ["images", "starts", "ends", "axis1"], ["red"]),
        helper.make_node("Reshape", ["red", "flat_shape"], ["flat"]),
        helper.make_node("ArgMax", ["flat"], ["index"], axis=1, keepdims=1),
        helper.make_node("ReduceMax", ["flat"], ["peak"], keepdims=1),
        helper.make_node("Reshape", ["peak", "score_shape"], ["scores"]),
        helper.make_node("Mod", ["index", "width"], ["col_i"]),
        helper.make_node("Div", ["index", "width"], ["row_i"]),
        helper.make_node("Cast", ["col_i"], ["col"], to=TensorProto.FLOAT),
        helper.make_node("Cast", ["row_i"], ["row"], to=TensorProto.FLOAT),
        helper.make_node("Add", ["col", "lo"], ["x0"]),
        helper.make_node("Add", ["row", "lo"], ["y0"]),
        helper.make_node("Add", ["col", "hi"], ["x1"]),
        helper.make_node("Add", ["row", "hi"], ["y1"]),
        helper.make_node("Concat", ["x0", "y0", "x1", "y1"], ["boxes"], axis=1),
    ]
    outputs = [
        helper.make_tensor_value_info("boxes", TensorProto.FLOAT, [1, 4]),
        helper.make_tensor_value_info("scores", TensorProto.FLOAT, [1]),
        helper.make_tensor_value_info("labels", TensorProto.INT64, [1]),
    ]
    graph = helper.make_graph(nodes, "brightest", [_image_input(size)], outputs)
    return _save(graph, path, None)


def rtdetr_model(path: Path, boxes: np.ndarray, scores: np.ndarray, labels: np.ndarray) -> Path:
    """An RT-DETR style model (``lyuwenyu/RT-DETR``'s deploy export): inputs ``images`` and
    ``orig_target_sizes`` ``[[w, h]]``, outputs ``labels``, ``boxes`` and ``scores``, the boxes
    given as fractions (``(1, N, 4)`` ``boxes``) and scaled by the sizes fed."""
    nodes = [
        helper.make_node(
            "Constant", [], [name], value=numpy_helper.from_array(np.asarray(value), name)
        )
        for name, value in (("labels", labels), ("fractions", boxes), ("scores", scores))
    ]
    nodes += [
        helper.make_node("Cast", ["orig_target_sizes"], ["wh"], to=TensorProto.FLOAT),
        helper.make_node("Concat", ["wh", "wh"], ["whwh"], axis=1),
        helper.make_node("Mul", ["fractions", "whwh"], ["boxes"]),
    ]
    inputs = [
        _image_input((64, 64)),
        helper.make_tensor_value_info("orig_target_sizes", TensorProto.INT64, [1, 2]),
    ]
    outputs = [
        helper.make_tensor_value_info("labels", TensorProto.INT64, list(labels.shape)),
        helper.make_tensor_value_info("boxes", TensorProto.FLOAT, list(boxes.shape)),
        helper.make_tensor_value_info("scores", TensorProto.FLOAT, list(scores.shape)),
    ]
    return _save(helper.make_graph(nodes, "rtdetr", inputs, outputs), path, None)
