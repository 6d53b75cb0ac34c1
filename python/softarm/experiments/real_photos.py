"""False ripe calls on real photos with no blackberry in them: every detector of
:data:`~softarm.perception.detector.choice.DETECTORS` on the colour photos that
scikit-image and scikit-learn ship in their wheels (a person, a cat, coffee, a
motorbike's stereo pair, a rocket on its pad, a retina, a stained tissue slide, a
palace among trees, a flower; the grey textures of grass, gravel and brick), none of
which holds a blackberry, so that every ripe call is a false one. The figures are
written as JSON (docs/data/real_photos.json) and printed as the table of
docs/perception.md ("Real photos"); ``--draw DIR`` writes one annotated picture per
photo and detector.

    pip install scikit-image scikit-learn   # only for this script: their photos
    python -m softarm.experiments.real_photos --out docs/data/real_photos.json

No photo here was seen while the detectors were trained or tuned. Each photo is read
whole, through an ideal camera whose focal length is the photo's longer side (as
``softarm detect`` does without ``--camera``); there is no depth."""

from __future__ import annotations

import argparse
import importlib.resources
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import MissingDependencyError
from softarm.files.images import read_image
from softarm.perception.detector.choice import DETECTORS, detector
from softarm.perception.detector.draw import draw_detections, write_image
from softarm.vision.camera_model import CameraModel

__all__ = ["PHOTOS", "Photo", "false_ripe_calls", "main", "table"]


@dataclass(frozen=True)
class Photo:
    """A photo inside an installed package: ``package``'s folder ``folder``, file ``name``."""

    package: str
    folder: str
    name: str

    def read(self) -> npt.NDArray[np.uint8]:
        """The photo as BGR (grey photos as three equal channels).

        Raises:
            MissingDependencyError: the package is not installed.
            InputError: the package lacks the photo.
        """
        try:
            root = importlib.resources.files(self.package)
        except ModuleNotFoundError as exc:
            raise MissingDependencyError(
                f"the real photos come from {self.package}: pip install scikit-image scikit-learn",
                self.package,
            ) from exc
        path = root.joinpath(self.folder, self.name)
        image = read_image(str(path), "photo", cv2.IMREAD_COLOR)
        return np.asarray(image, dtype=np.uint8)


_SKIMAGE = ("astronaut.png chelsea.png coffee.png motorcycle_left.png motorcycle_right.png "
            "rocket.jpg retina.jpg ihc.png grass.png gravel.png brick.png")  # fmt: skip
#: The photos scored: every real photograph the two wheels ship (not the drawings,
#: microscope cells, astronomy or test charts).
PHOTOS = tuple(Photo("skimage", "data", n) for n in _SKIMAGE.split()) + tuple(
    Photo("sklearn", "datasets/images", n) for n in ("china.jpg", "flower.jpg")
)


def false_ripe_calls(image: npt.NDArray[np.uint8], name: str) -> tuple[int, int, list[Any]]:
    """(ripe calls, all calls, the detections) of detector ``name`` on ``image``."""
    height, width = image.shape[:2]
    camera = CameraModel.ideal(float(max(width, height)), width, height)
    dets = list(detector(name).detect_berries(image, camera))
    return sum(d.ripeness == "ripe" for d in dets), len(dets), dets


def run(draw: Path | None = None) -> dict[str, Any]:
    """Per detector: the ripe and all calls on each photo, and the share of photos with
    at least one ripe call."""
    results: dict[str, Any] = {}
    images = {p.name: p.read() for p in PHOTOS}
    for name in DETECTORS:
        per_photo = {}
        for photo, image in images.items():
            ripe, calls, dets = false_ripe_calls(image, name)
            per_photo[photo] = {"ripe_calls": ripe, "calls": calls}
            if draw is not None:
                stem = Path(photo).stem
                write_image(
                    draw / f"{stem}_{name.replace('+', '_')}.jpg", draw_detections(image, dets)
                )
        flagged = sum(v["ripe_calls"] > 0 for v in per_photo.values())
        results[name] = {
            "photos": len(images),
            "photos_with_ripe_call": flagged,
            "share_with_ripe_call": round(flagged / len(images), 3),
            "ripe_calls": sum(v["ripe_calls"] for v in per_photo.values()),
            "per_photo": per_photo,
        }
    return results


def table(results: dict[str, Any]) -> str:
    """The Markdown table of docs/perception.md."""
    lines = ["| detector | photos with a ripe call | ripe calls in all | photos |",
             "| --- | ---: | ---: | ---: |"]  # fmt: skip
    for name, r in results.items():
        lines.append(
            f"| {name} | {r['photos_with_ripe_call']} ({r['share_with_ripe_call']:.0%}) "
            f"| {r['ripe_calls']} | {r['photos']} |"
        )
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, help="write the figures here (JSON)")
    parser.add_argument("--draw", type=Path, help="write annotated pictures into this folder")
    args = parser.parse_args(argv)
    cv2.setNumThreads(1)
    results = run(args.draw)
    if args.out is not None:
        from softarm.experiments.output import write_json

        write_json(args.out, {"photos": [f"{p.package}: {p.name}" for p in PHOTOS], **results})
    print(table(results))


if __name__ == "__main__":
    main()
