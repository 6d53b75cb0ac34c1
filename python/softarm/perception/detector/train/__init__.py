"""Training the learned berry detector (``softarm detector train``): JAX and optax, in the
``train`` extra, imported only here, so that the runtime never needs them.

:func:`train` reads ``softarm dataset`` output (or any COCO with masks: labelled photos),
trains the U-Net of :mod:`.unet` on augmented crops (:mod:`.augment`) and writes it as
ONNX (:mod:`.onnx_export`) with a JSON record of the run beside it. docs/perception.md
("The learned detector") has the recipe.
"""

from __future__ import annotations

import importlib.util
import json
import platform
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from softarm.errors import InputError, SoftarmError

__all__ = ["TrainExtraMissing", "require_train_extra", "train"]

_MODULES = ("jax", "optax", "onnx")


class TrainExtraMissing(SoftarmError, ImportError):
    """A module of the ``train`` extra is not installed."""


def require_train_extra() -> None:
    """Raise one line naming the extra when JAX, optax or onnx is missing.

    Raises:
        TrainExtraMissing: a module of the ``train`` extra is not installed.
    """
    missing = [m for m in _MODULES if importlib.util.find_spec(m) is None]
    if missing:
        raise TrainExtraMissing(
            f"training needs {', '.join(missing)}: pip install 'softarm[train]'"
        )


def train(
    data: list[str | Path],
    out: str | Path,
    epochs: int = 150,
    seed: int = 0,
    start: str | Path | None = None,
    on_epoch: Callable[[int, float, float], None] = lambda e, loss, s: None,
    widths: tuple[int, ...] | None = None,
    scale: tuple[float, float] | None = None,
    stem: bool = False,
    zooms: list[float] | None = None,
    heatmap: str | None = None,
    boundary: bool = False,
    distance: bool = False,
) -> dict[str, Any]:
    """Train on the COCO data folders ``data`` and write the network to ``out`` (ONNX)
    and its record to ``out`` with ``.json`` for a suffix; ``start`` is an ONNX file of
    this architecture to fine-tune (the shipped weights for ``--from default``; its
    widths are the file's). ``widths`` are a fresh network's four channel counts and
    ``scale`` the augmentation's scale range (defaults: :data:`.unet.WIDTHS`,
    :data:`.augment.SCALE`). ``stem``: a fresh network with the stride-2 stem (run on
    images twice the size: the samples are shrunk to twice MAX_SIDE and cropped twice as
    large; a fine-tuned one keeps its file's); ``zooms``: one scale factor per data folder
    (default 1; 2 for renders drawn at half the size the network runs at); ``heatmap``:
    the centre heatmap's loss, "logistic" or "focal" (CenterNet's: sharp peaks, which
    the record tells the run-time decoding, :mod:`..network`; default: the ``start``
    file's, from its record, else logistic); ``boundary``: a fresh network with the
    boundary class (the pixels of a fruit against another's, :mod:`..boundary`; a
    fine-tuned one keeps its file's); ``distance``: the network learns each fruit pixel's
    distance to its fruit's edge over the fruit's largest (:mod:`..distance`), a fresh
    network with that output or, with ``start``, the file's network with it added when
    it has none (a fine-tuned network that has it keeps it). Returns the record.

    Raises:
        TrainExtraMissing: the ``train`` extra is not installed.
        InputError: a data folder holds no labelled image, ``start`` is not a network
            of this architecture, ``widths``, ``stem`` or ``boundary`` are given with
            ``start``, or
            ``widths``, ``scale``, ``zooms`` or ``heatmap`` are not valid.
        VisionError: ``start``'s training record is unreadable.
    """
    require_train_extra()
    from softarm.perception.detector.network import MAX_SIDE
    from softarm.perception.detector.train.augment import SCALE
    from softarm.perception.detector.train.loop import TrainSettings, fit
    from softarm.perception.detector.train.onnx_export import export_onnx
    from softarm.perception.detector.train.samples import describe, load_samples
    from softarm.perception.detector.train.unet import WIDTHS, layers, widths_of

    heatmap = _checked(start, widths, stem or boundary, scale, heatmap)
    layers(WIDTHS if widths is None else widths)  # checks them before the data is read
    params = None
    if start is not None:
        params, stem, boundary, distance = _started(Path(start), distance, seed)
    samples, notes = load_samples(
        list(data), MAX_SIDE * (2 if stem else 1), zooms, boundary, distance
    )
    settings = TrainSettings(
        epochs=epochs, seed=seed,
        widths=widths_of(params) if params is not None else widths or WIDTHS,
        scale=SCALE if scale is None else scale, stem=stem, heatmap=heatmap, boundary=boundary,
        distance=distance,
    )  # fmt: skip
    began = time.perf_counter()
    params = fit(samples, settings, params, on_epoch)
    export_onnx(params, out)
    record = _record(out, notes, describe(samples), start, settings, began)
    from softarm.files import write_text

    write_text(Path(out).with_suffix(".json"), json.dumps(record, indent=1) + "\n", "record")
    return record


def _started(start: Path, distance: bool, seed: int) -> tuple[Any, bool, bool, bool]:
    """The parameters of the network ``start`` to fine-tune, whether it has the stem, the
    boundary class and (once added where ``distance`` asks for it and it has none, a
    fresh column of its head drawn from ``seed``) the distance output."""
    from softarm.perception.detector.network import distance_of
    from softarm.perception.detector.train.onnx_export import params_from_onnx
    from softarm.perception.detector.train.unet import has_boundary, stem_of, with_distance

    params = params_from_onnx(start)
    had = distance_of(start)
    boundary = has_boundary(params, had)
    if distance and not had:  # a fresh output on the trained network
        params = with_distance(params, seed)
    return params, stem_of(params), boundary, distance or had


def _checked(
    start: str | Path | None,
    widths: tuple[int, ...] | None,
    stem: bool,
    scale: tuple[float, float] | None,
    heatmap: str | None,
) -> str:
    """The heatmap loss :func:`train` uses, once its options are checked (an
    :class:`InputError` naming the bad one)."""
    from softarm.perception.detector.network import HEATMAPS, heatmap_of

    if start is not None and (widths is not None or stem):
        raise InputError(
            "widths, stem, boundary: a fine-tuned network keeps the widths, stem and boundary "
            "class of its --from file"
        )
    if scale is not None and not 0 < scale[0] <= scale[1]:
        raise InputError(f"scale {scale!r}: a range LOW <= HIGH of positive factors expected")
    if heatmap is None:
        heatmap = "logistic" if start is None else heatmap_of(Path(start))
    if heatmap not in HEATMAPS:
        raise InputError(f"heatmap {heatmap!r}: one of {', '.join(HEATMAPS)} expected")
    return heatmap


def _record(
    out: str | Path,
    notes: Any,
    pixels: str,
    start: str | Path | None,
    settings: Any,
    began: float,
) -> dict[str, Any]:
    """The training record written beside the weights ``out``."""
    import jax

    return {
        "weights": Path(out).name,
        "data": notes,
        "pixels": json.loads(pixels),
        "from": None if start is None else str(start),
        "epochs": settings.epochs,
        "seed": settings.seed,
        "batch": settings.batch,
        "learning_rate": settings.learning_rate,
        "widths": list(settings.widths),
        "scale": list(settings.scale),
        "stem": settings.stem,
        "heatmap": settings.heatmap,
        "boundary": settings.boundary,
        "distance": settings.distance,
        "losses": [round(v, 5) for v in settings.losses],
        "seconds": round(time.perf_counter() - began, 1),
        "device": str(jax.devices()[0].platform),
        "machine": platform.machine(),
    }
