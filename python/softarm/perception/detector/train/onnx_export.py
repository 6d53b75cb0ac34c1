"""The trained U-Net (:mod:`.unet`) written as an ONNX graph with ``onnx.helper``: the
same layers as :func:`.unet.apply`, NCHW, opset 13, the operators OpenCV's DNN module
runs (Conv, Relu, MaxPool, Resize nearest, Concat; the stem is a Conv of stride 2). The
convention of the input and
output is :mod:`softarm.perception.detector.network`'s."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from softarm.perception.detector.network import N_OUTPUTS, distance_of
from softarm.perception.detector.train.unet import STEM_KERNEL, Params, layers

__all__ = ["export_onnx", "onnx_bytes", "params_from_onnx"]

OPSET = 13


class _Graph:
    """Nodes and initialisers, named in order."""

    def __init__(self, helper: Any, numpy_helper: Any) -> None:
        self.h, self.nh = helper, numpy_helper
        self.nodes: list[Any] = []
        self.inits: list[Any] = []
        self._n = 0

    def _name(self, stem: str) -> str:
        self._n += 1
        return f"{stem}_{self._n}"

    def conv(self, params: Params, name: str, x: str, relu: bool = True) -> str:
        w, b = (np.asarray(a, np.float32) for a in params[name])
        k = w.shape[0]
        self.inits.append(
            self.nh.from_array(np.ascontiguousarray(w.transpose(3, 2, 0, 1)), f"{name}.w")
        )
        self.inits.append(self.nh.from_array(b, f"{name}.b"))
        y = self._name(name)
        stride = 2 if k == STEM_KERNEL else 1  # the stem (unet._conv)
        pad = k // 2 - (stride - 1)
        self.nodes.append(
            self.h.make_node(
                "Conv", [x, f"{name}.w", f"{name}.b"], [y], kernel_shape=[k, k],
                pads=[pad, pad, pad, pad], strides=[stride, stride],
            )
        )  # fmt: skip
        if not relu:
            return y
        r = self._name(f"{name}_relu")
        self.nodes.append(self.h.make_node("Relu", [y], [r]))
        return r

    def pool(self, x: str) -> str:
        y = self._name("pool")
        self.nodes.append(
            self.h.make_node("MaxPool", [x], [y], kernel_shape=[2, 2], strides=[2, 2])
        )
        return y

    def up_cat(self, low: str, skip: str) -> str:
        if not any(i.name == "up.scales" for i in self.inits):
            scales = np.array([1.0, 1.0, 2.0, 2.0], np.float32)
            self.inits.append(self.nh.from_array(scales, "up.scales"))
        u = self._name("up")
        self.nodes.append(
            self.h.make_node(
                "Resize", [low, "", "up.scales"], [u], mode="nearest",
                coordinate_transformation_mode="asymmetric", nearest_mode="floor",
            )
        )  # fmt: skip
        c = self._name("cat")
        self.nodes.append(self.h.make_node("Concat", [u, skip], [c], axis=1))
        return c


def onnx_bytes(params: Params) -> bytes:
    """The serialised ONNX model of ``params``."""
    import onnx
    from onnx import helper, numpy_helper

    g = _Graph(helper, numpy_helper)
    s1 = g.conv(params, "enc1", "image")
    s2 = g.conv(params, "enc2b", g.conv(params, "enc2a", g.pool(s1)))
    s3 = g.conv(params, "enc3b", g.conv(params, "enc3a", g.pool(s2)))
    s4 = g.conv(params, "enc4b", g.conv(params, "enc4a", g.pool(s3)))
    d3 = g.conv(params, "dec3", g.up_cat(s4, s3))
    d2 = g.conv(params, "dec2", g.up_cat(d3, s2))
    d1 = g.conv(params, "dec1", g.up_cat(d2, s1))
    head = g.conv(params, "head", d1, relu=False)
    outputs = int(np.asarray(params["head"][1]).shape[0])  # N_OUTPUTS, +1 with the boundary
    g.nodes.append(helper.make_node("Identity", [head], ["scores"]))
    f32 = onnx.TensorProto.FLOAT
    graph = helper.make_graph(
        g.nodes, "softarm_berries",
        [helper.make_tensor_value_info("image", f32, [1, 3, "height", "width"])],
        [helper.make_tensor_value_info("scores", f32, [1, outputs, "height", "width"])],
        g.inits,
    )  # fmt: skip
    model = helper.make_model(
        graph, producer_name="softarm", opset_imports=[helper.make_opsetid("", OPSET)]
    )
    model.ir_version = 8
    onnx.checker.check_model(model)
    data: bytes = model.SerializeToString()
    return data


def export_onnx(params: Params, path: str | Path) -> None:
    """Write ``params`` as an ONNX file at ``path`` (atomically)."""
    from softarm.files import atomic_path

    with atomic_path(path) as tmp:
        Path(tmp).write_bytes(onnx_bytes(params))


def params_from_onnx(path: str | Path) -> Params:
    """The parameters of an ONNX file this module wrote (to fine-tune it).

    Raises:
        InputError: the file is missing, unreadable, or not this architecture.
        VisionError: its training record (which says whether a seventh output is the
            boundary class or the distance) is unreadable.
    """
    import jax.numpy as jnp
    import onnx
    from onnx import numpy_helper

    from softarm.errors import InputError

    try:
        model = onnx.load(str(path))
    except FileNotFoundError:
        raise InputError(f"--from {path}: no such file") from None
    except Exception as exc:  # onnx raises protobuf's DecodeError and others
        raise InputError(f"--from {path}: not a readable ONNX file ({exc})") from None
    arrays = {i.name: numpy_helper.to_array(i) for i in model.graph.initializer}
    # The widths are the file's: each level's first convolution's output channels.
    firsts = [arrays.get(f"{n}.w") for n in ("enc1", "enc2a", "enc3a", "enc4a")]
    if any(w is None or w.ndim != 4 for w in firsts):
        raise InputError(f"--from {path}: not a network of this architecture (no U-Net levels)")
    widths = tuple(int(w.shape[0]) for w in firsts if w is not None)
    stem = firsts[0] is not None and int(firsts[0].shape[-1]) == STEM_KERNEL
    head = arrays.get("head.w")
    # A seventh output is the boundary class's or the distance's: the record says which.
    distance = distance_of(Path(path))
    boundary = head is not None and int(head.shape[0]) - int(distance) == N_OUTPUTS + 1
    params: Params = {}
    for name, k, cin, cout in layers(widths, stem, boundary, distance):
        w, b = arrays.get(f"{name}.w"), arrays.get(f"{name}.b")
        if w is None or b is None or w.shape != (cout, cin, k, k) or b.shape != (cout,):
            raise InputError(f"--from {path}: not a network of this architecture (layer {name})")
        kernel = np.ascontiguousarray(w.transpose(2, 3, 1, 0), np.float32)
        params[name] = (jnp.asarray(kernel), jnp.asarray(b.astype(np.float32)))
    return params
