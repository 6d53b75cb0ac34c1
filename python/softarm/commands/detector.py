"""``softarm detector evaluate|train``: the berry detector measured on labelled images, and
the learned one trained (the ``train`` extra) on rendered or labelled images."""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

from softarm.commands._args import add_quiet, int_range, output_dir, output_file
from softarm.commands.detect import add_split_touching

#: Most epochs a user may ask for (a typo's extra zeros, not a real run).
MAX_EPOCHS = 10_000


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``detector`` subcommand and its two actions."""
    p = sub.add_parser(
        "detector",
        help="evaluate the berry detector on labelled images, or train the learned one",
        description="evaluate: precision, recall, ripeness, a confusion table by stage and "
        "one annotated picture per image, against COCO labels (softarm dataset, CVAT or "
        "Label Studio exports). train: the learned detector from softarm dataset output or "
        "labelled photos (needs the train extra). See docs/perception.md.",
    )
    actions = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    _add_evaluate(actions)
    _add_train(actions)


def _add_evaluate(actions: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    from softarm.perception.detector.choice import DEFAULT_DETECTOR, DETECTORS

    e = actions.add_parser(
        "evaluate",
        help="score a detector against COCO labels",
        description="A detection matches a labelled fruit at mask IoU >= 0.3; recall and "
        "stage count fruit at least half visible (or of unknown share). --depth: a folder "
        "of depth images named as the images (16-bit PNG mm or .npy m) adds the "
        "localisation error; --camera: the camera file (default: each image's camera in "
        "the COCO file, else an ideal one).",
    )
    e.add_argument("--images", type=Path, required=True, help="folder of the images")
    e.add_argument("--labels", type=Path, required=True, help="COCO file")
    e.add_argument("--depth", type=Path, help="folder of aligned depth images")
    e.add_argument("--camera", type=Path, help="camera file")
    e.add_argument("--out", type=output_dir, help="folder for metrics.json and the pictures")
    e.add_argument("--detector", choices=DETECTORS, default=DEFAULT_DETECTOR, help="detector")
    add_split_touching(e)
    add_quiet(e)
    e.set_defaults(run=run_evaluate)


def _add_train(actions: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    t = actions.add_parser(
        "train",
        help="train the learned detector (the train extra: JAX, optax, onnx)",
        description="Trains the segmentation network on augmented crops of the images of "
        "each --data folder (softarm dataset output, or a folder with one COCO file of "
        "labelled photos; --data may be given more than once, to mix photos with renders) "
        "and writes it as ONNX, with OUT's name and .json for the training record. "
        "Deterministic for a seed. --from default fine-tunes the shipped weights.",
    )
    t.add_argument("--data", type=Path, action="append", required=True, help="data folder")
    t.add_argument("--out", type=output_file, required=True, help="ONNX file to write")
    t.add_argument("--epochs", type=int_range(1, MAX_EPOCHS), default=150, help="epochs")
    t.add_argument("--seed", type=int_range(0, 2**31 - 1), default=0, help="seed")
    t.add_argument(
        "--widths", type=_numbers(int, 4), metavar="C1,C2,C3,C4",
        help="a fresh network's channels at full, 1/2, 1/4 and 1/8 resolution (default 8,16,24,32)",
    )  # fmt: skip
    t.add_argument(
        "--scale", type=_numbers(float, 2), metavar="LOW,HIGH",
        help="range of the augmentation's scale factor (default 0.6,1.7); shift it up for a "
        "network run on images larger than its training renders",
    )  # fmt: skip
    t.add_argument(
        "--stem", action="store_true",
        help="a fresh network with a stride-2 first layer: it sees the full image's detail "
        "and runs the rest at half size (trained and run at twice the size: 1280 px)",
    )  # fmt: skip
    t.add_argument(
        "--zoom", type=float, action="append", metavar="F",
        help="scale factor of each --data folder, in order (default 1 each; 2 for renders "
        "drawn at --scale 0.5 for a network run at full size)",
    )  # fmt: skip
    t.add_argument(
        "--heatmap", choices=("logistic", "focal"),
        help="the centre heatmap's loss: logistic (default; with --from, that file's) or "
        "CenterNet's focal loss, whose sharp peaks split touching fruit (the record beside "
        "OUT tells the detector)",
    )  # fmt: skip
    t.add_argument(
        "--boundary", action="store_true",
        help="a fresh network with a boundary class (the pixels of a fruit against another "
        "fruit), removed before the fruit pixels are split into parts, so that touching "
        "fruit fall apart (the record beside OUT tells the detector)",
    )  # fmt: skip
    t.add_argument(
        "--distance", action="store_true",
        help="the network also learns each fruit pixel's distance to its fruit's edge over "
        "the fruit's largest, and touching fruit are split by a watershed of it (with "
        "--from, added to that file's network; the record beside OUT tells the detector)",
    )  # fmt: skip
    t.add_argument(
        "--from", dest="start", metavar="WEIGHTS",
        help="start from these weights ('default': the shipped ones) instead of fresh ones",
    )  # fmt: skip
    add_quiet(t)
    t.set_defaults(run=run_train)


def _numbers(kind: type[int] | type[float], count: int) -> Callable[[str], tuple[Any, ...]]:
    """A ``type=`` accepting ``count`` positive comma-separated numbers of ``kind``."""

    def parse(text: str) -> tuple[Any, ...]:
        try:
            values = tuple(kind(v) for v in text.split(","))
        except ValueError:
            values = ()
        if len(values) != count or not all(math.isfinite(v) and v > 0 for v in values):
            raise argparse.ArgumentTypeError(
                f"must be {count} positive {kind.__name__}s separated by commas, got {text!r}"
            )
        return values

    parse.__name__ = f"{count} {kind.__name__}s"
    return parse


def run_evaluate(args: argparse.Namespace) -> int:
    """Exit 0 with the figures printed (and written with --out)."""
    from softarm.commands._progress import Progress
    from softarm.commands.detect import split_settings
    from softarm.perception.detector.choice import detector
    from softarm.perception.detector.evaluate import evaluate
    from softarm.vision.camera_model import CameraModel

    det = detector(args.detector)
    camera = None if args.camera is None else CameraModel.load(args.camera)
    with Progress(None, "evaluate", "image", args.quiet) as progress:
        figures = evaluate(
            det, args.labels, args.images, args.depth, camera, args.out, progress.advance,
            split_settings(args),
        )  # fmt: skip
    shown = {k: v for k, v in figures.items() if k != "per_image"}
    print(json.dumps(shown, indent=1))
    if args.out is not None:
        print(f"detector evaluate: {figures['images']} images -> {args.out}")
    return 0


def run_train(args: argparse.Namespace) -> int:
    """Exit 0 once the weights and their record are written."""
    from softarm.perception.detector.network import DEFAULT_WEIGHTS
    from softarm.perception.detector.train import require_train_extra, train

    require_train_extra()
    start = DEFAULT_WEIGHTS if args.start == "default" else args.start

    def on_epoch(epoch: int, loss: float, seconds: float) -> None:
        if not args.quiet:
            print(f"epoch {epoch}/{args.epochs}: loss {loss:.4f} ({seconds:.1f} s)", flush=True)

    record = train(
        args.data, args.out, args.epochs, args.seed, start, on_epoch, args.widths, args.scale,
        args.stem, args.zoom, args.heatmap, args.boundary, args.distance,
    )  # fmt: skip
    print(
        f"detector train: {args.epochs} epochs in {record['seconds']} s on "
        f"{record['device']} -> {args.out} (record {Path(args.out).with_suffix('.json')})"
    )
    return 0


__all__ = ["add_parser"]
