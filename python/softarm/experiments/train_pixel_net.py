"""Train the pixel network of :mod:`softarm.perception.net_berries` on rendered bushes.

Each bush is rendered as :mod:`softarm.experiments.perception` renders it (10 berries,
40 % unripe, no arm, C1's left eye, rectified), with its truth: every pixel background,
ripe berry or unripe berry. Pixels are sampled per image (fruit of each class, random
background, the background ring around the fruit, dark background and the clutter, the
dark look-alikes that ripe fruit is confused with) and an MLP of one tanh hidden layer
is trained on their features (:func:`~softarm.perception.net_berries.pixel_features`)
with a softmax cross-entropy, Adam, in numpy. The network is written as ONNX (Gemm,
Tanh, Gemm; the protobuf is written here, so that no onnx package is needed) and read
back through OpenCV's DNN module, which must give the numpy outputs.

The hidden layer's width, 8, is the smallest of 8, 16 and 32 whose detections on the
validation bushes (940–949, 0–4, through :mod:`softarm.experiments.perception`) met the
issue's goals: all three gave precision, recall and ripeness 1.000 there.

Only tuning seeds: train on bushes 900–939, validate on 940–949 and 0–4 (never the
600–699 evaluation bushes)::

    MUJOCO_GL=egl python -m softarm.experiments.train_pixel_net --out pixels.onnx
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.perception.net_berries import N_CLASSES, N_FEATURES, NetDetector, pixel_features

__all__ = ["Mlp", "onnx_model", "rendered", "sample_pixels", "train"]

_U8 = npt.NDArray[np.uint8]
_F32 = npt.NDArray[np.float32]

#: Pixels sampled per image: each fruit class, random background, the ring around the
#: fruit, dark background, clutter (look-alikes).
PER_IMAGE = {"fruit": 3000, "background": 30000, "ring": 4000, "dark": 6000, "clutter": 4000}
#: Truth codes: the network's classes, and the clutter (a background class).
CLUTTER = 3
#: The ring's width (px) around the fruit.
RING = 7
#: A background pixel this dark (V of HSV) is sampled as a hard negative.
DARK_V = 90
TRAIN_SEEDS = range(900, 940)
VALIDATION_SEEDS = (*range(940, 950), *range(5))


@dataclass(frozen=True)
class Mlp:
    """One hidden layer: logits = tanh(x W1 + b1) W2 + b2."""

    W1: _F32
    b1: _F32
    W2: _F32
    b2: _F32

    def logits(self, x: _F32) -> _F32:
        """(N, N_CLASSES) logits of (N, N_FEATURES) features."""
        return cast(_F32, np.tanh(x @ self.W1 + self.b1) @ self.W2 + self.b2)


def sample_pixels(
    image: _U8, truth: _U8, rng: np.random.Generator, per_image: dict[str, int] | None = None
) -> tuple[_F32, npt.NDArray[np.int64]]:
    """(features (N, N_FEATURES), classes (N,)) of pixels sampled from one image whose
    ``truth`` (H, W) holds 0 background, 1 ripe, 2 unripe, CLUTTER (background)."""
    n = per_image or PER_IMAGE
    feats = pixel_features(image).reshape(-1, N_FEATURES)
    flat = truth.reshape(-1)
    fruit = ((truth == 1) | (truth == 2)).astype(np.uint8)
    ring = cv2.dilate(fruit, np.ones((2 * RING + 1, 2 * RING + 1), np.uint8)).reshape(-1) > 0
    value = cast(_U8, cv2.cvtColor(image, cv2.COLOR_BGR2HSV))[..., 2].reshape(-1)
    background = (flat == 0) | (flat == CLUTTER)
    pools = [
        (np.flatnonzero(flat == 1), n["fruit"]),
        (np.flatnonzero(flat == 2), n["fruit"]),
        (np.flatnonzero(background), n["background"]),
        (np.flatnonzero(background & ring), n["ring"]),
        (np.flatnonzero(background & (value <= DARK_V)), n["dark"]),
        (np.flatnonzero(flat == CLUTTER), n["clutter"]),
    ]
    picks = [rng.choice(p, min(k, p.size), replace=False) for p, k in pools if p.size]
    idx = np.concatenate(picks) if picks else np.zeros(0, np.int64)
    classes = flat[idx].astype(np.int64)
    classes[classes == CLUTTER] = 0
    return feats[idx], classes


def train(
    x: _F32,
    y: npt.NDArray[np.int64],
    hidden: int = 8,
    epochs: int = 20,
    batch: int = 2048,
    rate: float = 0.01,
    seed: int = 0,
) -> Mlp:
    """An :class:`Mlp` fitted to features ``x`` and classes ``y`` by minibatch Adam on
    the mean softmax cross-entropy."""
    rng = np.random.default_rng(seed)
    f = x.shape[1]
    params = [
        (rng.normal(size=(f, hidden)) / np.sqrt(f)).astype(np.float32),
        np.zeros(hidden, np.float32),
        (rng.normal(size=(hidden, N_CLASSES)) / np.sqrt(hidden)).astype(np.float32),
        np.zeros(N_CLASSES, np.float32),
    ]
    m = [np.zeros_like(p) for p in params]
    v = [np.zeros_like(p) for p in params]
    b1, b2, eps = 0.9, 0.999, 1e-8
    step = 0
    onehot = np.eye(N_CLASSES, dtype=np.float32)
    for _ in range(epochs):
        order = rng.permutation(len(x))
        for start in range(0, len(x), batch):
            i = order[start : start + batch]
            xb, tb = x[i], onehot[y[i]]
            W1, c1, W2, c2 = params
            h = np.tanh(xb @ W1 + c1)
            z = h @ W2 + c2
            p = np.exp(z - z.max(axis=1, keepdims=True))
            p /= p.sum(axis=1, keepdims=True)
            dz = (p - tb) / len(i)
            dh = (dz @ W2.T) * (1.0 - h * h)
            grads = [xb.T @ dh, dh.sum(0), h.T @ dz, dz.sum(0)]
            step += 1
            for k, g in enumerate(grads):
                m[k] = b1 * m[k] + (1 - b1) * g
                v[k] = b2 * v[k] + (1 - b2) * g * g
                mhat = m[k] / (1 - b1**step)
                vhat = v[k] / (1 - b2**step)
                params[k] = (params[k] - rate * mhat / (np.sqrt(vhat) + eps)).astype(np.float32)
    return Mlp(*params)


# --- ONNX, written by hand (protobuf wire format; onnx.proto's field numbers) ---------


def _varint(n: int) -> bytes:
    out = bytearray()
    while True:
        low, n = n & 0x7F, n >> 7
        out.append(low | 0x80 if n else low)
        if not n:
            return bytes(out)


def _int(field: int, value: int) -> bytes:
    return _varint(field << 3) + _varint(value)


def _bytes(field: int, data: bytes) -> bytes:
    return _varint(field << 3 | 2) + _varint(len(data)) + data


def _str(field: int, text: str) -> bytes:
    return _bytes(field, text.encode())


def _tensor(name: str, array: _F32) -> bytes:
    """TensorProto: dims (1), data_type FLOAT (2), name (8), raw_data (9)."""
    a = np.ascontiguousarray(array, dtype="<f4")
    dims = b"".join(_int(1, d) for d in a.shape)
    return dims + _int(2, 1) + _str(8, name) + _bytes(9, a.tobytes())


def _value_info(name: str, dims: Sequence[int | str]) -> bytes:
    """ValueInfoProto of a float tensor: name (1), type (2) → tensor_type (1) →
    elem_type (1), shape (2) → dim (1) → dim_value (1) | dim_param (2)."""
    shape = b"".join(_bytes(1, _int(1, d) if isinstance(d, int) else _str(2, d)) for d in dims)
    return _str(1, name) + _bytes(2, _bytes(1, _int(1, 1) + _bytes(2, shape)))


def _node(op: str, inputs: Sequence[str], outputs: Sequence[str], name: str) -> bytes:
    """NodeProto: input (1), output (2), name (3), op_type (4)."""
    return (
        b"".join(_str(1, i) for i in inputs)
        + b"".join(_str(2, o) for o in outputs)
        + _str(3, name)
        + _str(4, op)
    )


def onnx_model(mlp: Mlp) -> bytes:
    """``mlp`` as an ONNX model (IR 8, opset 13): features (n, N_FEATURES) → logits."""
    nodes = [
        _node("Gemm", ["features", "W1", "b1"], ["hidden"], "fc1"),
        _node("Tanh", ["hidden"], ["activation"], "tanh"),
        _node("Gemm", ["activation", "W2", "b2"], ["logits"], "fc2"),
    ]
    weights = {"W1": mlp.W1, "b1": mlp.b1, "W2": mlp.W2, "b2": mlp.b2}
    graph = (
        b"".join(_bytes(1, n) for n in nodes)
        + _str(2, "berry_pixels")
        + b"".join(_bytes(5, _tensor(k, a)) for k, a in weights.items())
        + _bytes(11, _value_info("features", ["n", N_FEATURES]))
        + _bytes(12, _value_info("logits", ["n", N_CLASSES]))
    )
    opset = _str(1, "") + _int(2, 13)
    return _int(1, 8) + _str(2, "softarm.train_pixel_net") + _bytes(7, graph) + _bytes(8, opset)


# --- rendered data ----------------------------------------------------------------------


def rendered(seeds: Iterable[int]) -> Iterator[tuple[int, _U8, _U8]]:
    """(seed, rectified C1 left image, truth (H, W): 0 background, 1 ripe, 2 unripe,
    CLUTTER) of each bush, rendered as
    :func:`softarm.experiments.perception.evaluate_berries` renders it."""
    import softarm
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.bush import Bush
    from softarm.sim.render.labels import KINDS
    from softarm.sim.render.world import world_for
    from softarm.sim.rig_cameras import BASE_TAG_ID

    arm = softarm.SoftArm.blackberry()
    cams = default_cameras()
    for seed in seeds:
        bush = Bush.generate(arm, 10, seed, view_point=cams.T_base_c1[:3, 3], unripe_fraction=0.4)
        world = world_for(bush, cams, BASE_TAG_ID)
        frame = world.c1_left(truth=True)
        assert frame.geoms is not None
        kinds = world.labels.kinds(frame.geoms)
        truth = np.where(kinds == KINDS.index("clutter"), CLUTTER, 0).astype(np.uint8)
        for berry in bush.berries:
            mask = world.labels.mask(frame.geoms, "berry", berry.tag_id)
            truth[mask] = 1 if berry.ripeness >= 0.5 else 2
        mx, my = world.stereo.rectification.maps[0]
        image = cast(_U8, cv2.remap(frame.colour, mx, my, cv2.INTER_LINEAR))
        truth = cast(_U8, cv2.remap(truth, mx, my, cv2.INTER_NEAREST))
        world.close()
        yield seed, image, truth


def confusion(detector: NetDetector, images: Iterable[tuple[_U8, _U8]]) -> npt.NDArray[np.int64]:
    """(N_CLASSES, N_CLASSES) pixel counts, rows the truth, columns the network."""
    out = np.zeros((N_CLASSES, N_CLASSES), np.int64)
    for image, truth in images:
        c = detector.classes(image)
        t = np.where(truth == CLUTTER, 0, truth).astype(np.int64)
        out += np.bincount(
            t.reshape(-1) * N_CLASSES + c.reshape(-1),
            minlength=N_CLASSES**2,
        ).reshape(N_CLASSES, N_CLASSES)
    return out


def main(argv: Sequence[str] | None = None) -> None:
    """Render, sample, train, export, check through cv2.dnn, validate."""
    p = argparse.ArgumentParser(prog="python -m softarm.experiments.train_pixel_net")
    p.add_argument("--out", type=Path, required=True, help="the ONNX file to write")
    p.add_argument("--train", type=int, nargs=2, default=(900, 939), metavar=("FIRST", "LAST"))
    p.add_argument("--hidden", type=int, default=8)
    p.add_argument("--epochs", type=int, default=20)
    p.add_argument("--no-validate", action="store_true")
    a = p.parse_args(argv)
    if set(range(a.train[0], a.train[1] + 1)) & set(range(600, 700)):
        raise SystemExit("bushes 600–699 are for evaluation only")
    rng = np.random.default_rng(0)
    xs, ys = [], []
    t0 = time.perf_counter()
    for _, image, truth in rendered(range(a.train[0], a.train[1] + 1)):
        x, y = sample_pixels(image, truth, rng)
        xs.append(x)
        ys.append(y)
    x, y = np.concatenate(xs), np.concatenate(ys)
    counts = np.bincount(y, minlength=N_CLASSES)
    print(f"{len(x)} pixels {counts} ({time.perf_counter() - t0:.0f} s)")
    t0 = time.perf_counter()
    mlp = train(x, y, hidden=a.hidden, epochs=a.epochs)
    print(f"trained in {time.perf_counter() - t0:.0f} s")
    model = onnx_model(mlp)
    a.out.write_bytes(model)
    detector = NetDetector(a.out)
    probe = x[:1000]
    err = float(np.abs(detector._forward(probe) - mlp.logits(probe)).max())
    print(f"wrote {a.out} ({len(model)} bytes); cv2.dnn against numpy: {err:.2e}")
    if err > 1e-3:
        raise SystemExit("OpenCV's DNN module disagrees with the trained network")
    if not a.no_validate:
        cm = confusion(detector, ((im, t) for _, im, t in rendered(VALIDATION_SEEDS)))
        print("validation pixels (rows truth, columns net: background, ripe, unripe):")
        print(cm)
        for k in (1, 2):
            precision = cm[k, k] / max(cm[:, k].sum(), 1)
            recall = cm[k, k] / max(cm[k].sum(), 1)
            print(f"  {('', 'ripe', 'unripe')[k]}: precision {precision:.3f} recall {recall:.3f}")


if __name__ == "__main__":
    main()
