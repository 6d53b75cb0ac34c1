"""The perception map of the daylight row (``softarm sweep`` with a ``[perception]``
spec): its spec's errors, the row's look-alike and fruit-density knobs, the scoring, and
one cell end to end on a tiny render (C1 at 320 x 180, no shadows), table and picture
written."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from softarm.cli import main
from softarm.errors import ConfigError, ParameterError
from softarm.sweep import perception_map
from softarm.sweep.perception_score import cell_summary, stereo_counts
from softarm.sweep.perception_spec import PerceptionTrial, parse_perception_spec
from softarm.sweep.perception_trial import run_perception_trial, trial_look

ROOT = Path(__file__).resolve().parents[1]
TINY = ROOT / "examples" / "sweeps" / "row_robustness_tiny.toml"


def _spec(**table: Any) -> dict[str, Any]:
    return {"perception": {"seeds": [300000], **table}}


@pytest.mark.parametrize(
    ("doc", "key"),
    [
        ({"perception": {}}, "seeds"),
        (_spec(seeds=[1, 1]), "seeds"),
        (_spec(looks=["noon"]), "looks"),
        (_spec(looks=[]), "looks"),
        (_spec(effects=["half"]), "effects"),
        (_spec(lookalikes=["lots"]), "lookalikes"),
        (_spec(fruit=["heaps"]), "fruit"),
        (_spec(detectors=["yolo"]), "detectors"),
        (_spec(berries=0), "berries"),
        (_spec(scale=2.0), "scale"),
        (_spec(unripe_fraction=-0.1), "unripe_fraction"),
        (_spec(shadows="yes"), "shadows"),
        (_spec(colour=1), "colour"),
        ({**_spec(), "sweep": {}}, "[sweep]"),
    ],
)
def test_a_bad_spec_is_one_line_naming_the_key(doc: dict[str, Any], key: str) -> None:
    with pytest.raises(ConfigError) as err:
        parse_perception_spec(doc, "map.toml")
    message = str(err.value)
    assert "\n" not in message and message.startswith("map.toml: ")
    assert key in message


def test_the_command_refuses_a_bad_spec_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = tmp_path / "map.toml"
    spec.write_text('[perception]\nseeds = [300000]\nlooks = ["noon"]\n')
    assert main(["sweep", str(spec), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "[perception] looks: 'noon'" in err
    assert not (tmp_path / "out").exists()


def test_the_grid_is_every_cell_times_every_seed() -> None:
    spec = parse_perception_spec(_spec(seeds=[300000, 300001]))
    assert len(spec.cells()) == 4 * 2 * 2 * 2
    trials = spec.trials()
    assert len(trials) == 64 and len({t.trial_id for t in trials}) == 64


def test_the_row_knobs_change_what_the_row_holds() -> None:
    import softarm
    from softarm.sim.bush import Bush
    from softarm.sim.render.row import Row
    from softarm.sim.render.row_look import RowLook

    bush = Bush.generate(softarm.SoftArm.blackberry(), 8, 300500, unripe_fraction=0.3)

    def row(lookalikes: str, fruit: str) -> Row:
        return Row.generate(bush, RowLook.named("sun", 300500, lookalikes, fruit))

    few, many = row("few", "sparse"), row("many", "dense")
    assert sum(leaf.dead for leaf in many.leaflets) > 5 * sum(leaf.dead for leaf in few.leaflets)
    assert len(many.stones) > 5 * len(few.stones)
    assert len(many.fruit) > 3 * len(few.fruit)
    # "normal" is the row every look drew before the knobs: the defaults.
    default = Row.generate(bush, RowLook.named("sun", 300500))
    normal = row("normal", "normal")
    assert [f.fruit_id for f in default.fruit] == [f.fruit_id for f in normal.fruit]
    assert np.array_equal(default.stones, normal.stones)


@pytest.mark.parametrize(("kwargs", "name"), [({"lookalikes": "lots"}, "lookalikes"),
                                              ({"fruit": "heaps"}, "fruit")])  # fmt: skip
def test_a_bad_level_names_its_argument(kwargs: dict[str, str], name: str) -> None:
    from softarm.sim.render.row_look import RowLook

    with pytest.raises(ParameterError, match=f"^{name} must be one of"):
        RowLook.named("sun", 1, **kwargs)


def test_the_camera_levels() -> None:
    from softarm.sim.render.camera_effects import CameraEffects

    def look(effects: str) -> Any:
        return trial_look(PerceptionTrial("dusk", effects, "few", "sparse", 300000, ("colour",),
                                          8, 0.3, 1.0, True, True, True))  # fmt: skip

    on, off = look("on"), look("off")
    assert on.stereo.left.read_noise > 0 and on.blur_px_s > 0 and on.stereo.left.jpeg_quality
    # An ideal camera: auto-exposure alone, both eyes alike, no blur; the scene unchanged.
    assert off.stereo.left == CameraEffects() and off.stereo.left.exposure is None
    assert off.stereo.right_exposure == 1.0 and off.stereo.right_offset_px == (0.0, 0.0)
    assert off.blur_px_s == 0.0 and off.c2 == CameraEffects()
    assert off.sun_elevation == on.sun_elevation and off.ambient == on.ambient
    assert look("raw").stereo == on.stereo  # raw: the look's; the world applies none


def test_stereo_pairs_nearest_first_each_once() -> None:
    targets = {1: np.zeros(3), 2: np.array([0.021, 0.0, 0.0])}
    located = [np.array([0.004, 0.0, 0.0]), np.array([0.006, 0.0, 0.0]), np.array([1.0, 0, 0])]
    counts = stereo_counts(targets, located)
    # 0.004 -> fruit 1 (4 mm); 0.006 -> fruit 2 (15 mm: paired, not located); 1 m: none.
    assert counts == {"targets": 2, "located": 1, "errors_mm": [4.0, 15.0]}


def test_a_cell_pools_its_seeds_and_counts_failures() -> None:
    from dataclasses import asdict

    from softarm.perception.detector.scoring import Tally

    a, b = Tally(), Tally()
    a.detections, a.ripe_calls, a.ripe_calls_right = 4, 4, 3
    a.counted["ripe"], a.found["ripe"] = 5, 3
    b.detections, b.ripe_calls, b.ripe_calls_right = 2, 2, 1
    b.counted["ripe"], b.found["ripe"] = 3, 1

    def row(t: Tally, located: int) -> dict[str, Any]:
        stereo = {"targets": 4, "located": located, "errors_mm": [2.0, 8.0]}
        det = {"tally": asdict(t), "stereo": stereo}
        canes = {"coverage": 0.5, "precision": 1.0, "median_mm": 2.0, "median_all_mm": 9.0,
                 "length_m": 1.0, "fits": 2}  # fmt: skip
        return {"error": None, "fruit_in_view": 10, "ripe_targets": 4,
                "detectors": {"colour": det}, "canes": canes}  # fmt: skip

    no_fit = row(b, 1)
    # Two fits, both beyond the workspace: none in it (cane_map_error's precision 0).
    no_fit["canes"] = {"coverage": 0.0, "precision": 0.0, "median_mm": None,
                       "median_all_mm": None, "length_m": 1.0, "fits": 2}  # fmt: skip
    rows = [row(a, 2), row(b, 1), no_fit, {"error": "RuntimeError: x"}]
    rows[0]["detectors"]["colour"]["wrong_ripe_on"] = {"clutter": 1}
    rows[1]["detectors"]["colour"]["wrong_ripe_on"] = {"clutter": 2, "turning": 1}
    cell = cell_summary(rows, ["colour"])
    assert cell["frames"] == 3 and cell["failed"] == 1 and cell["ripe_targets"] == 12
    colour = cell["detectors"]["colour"]
    assert colour["ripe_precision"] == round(5 / 8, 3) and colour["recall_ripe"] == round(5 / 11, 3)
    assert colour["located"] == round(4 / 12, 3) and colour["stereo_median_mm"] == 5.0
    assert colour["wrong_ripe_on"] == {"clutter": 3, "turning": 1}
    # A frame without a fitted cane in the workspace lowers the coverage, not the precision.
    assert cell["canes"] == {"coverage": round(1 / 3, 3), "precision": 1.0, "median_mm": 2.0,
                             "frames_without_fit": 1}  # fmt: skip


def test_a_failing_trial_is_a_row_with_its_error() -> None:
    trial = PerceptionTrial("noon", "on", "few", "sparse", 300000, ("colour",), 2, 0.3, 0.25,
                            False, False, False)  # fmt: skip
    row = run_perception_trial(trial)
    assert row["error"].startswith("ParameterError: look must be one of")
    assert row["look"] == "noon" and row["seed"] == 300000


def test_one_cell_end_to_end_writes_the_table_and_the_picture(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from render_required import need_mujoco

    need_mujoco()
    monkeypatch.setattr(perception_map, "_want_ray", lambda use_ray: False)  # no Ray start
    out = tmp_path / "map"
    args = ["sweep", str(TINY), "--out", str(out), "--no-progress"]
    assert main(args) == 0, capsys.readouterr().err
    assert "1 trial run in this process (0 failed)" in capsys.readouterr().out
    doc = json.loads((out / "row_robustness.json").read_text())
    (cell,) = doc["cells"]
    assert (cell["look"], cell["effects"], cell["lookalikes"], cell["fruit"]) == (
        "overcast", "on", "many", "sparse",
    )  # fmt: skip
    assert cell["frames"] == 1 and cell["failed"] == 0
    assert cell["fruit_in_view"] > 0 and cell["ripe_targets"] > 0
    assert set(cell["detectors"]) == {"colour"} and "located" in cell["detectors"]["colour"]
    canes = cell["canes"]  # at this size C1 may fit no cane: no precision then
    assert 0.0 <= canes["coverage"] <= 1.0 and canes["frames_without_fit"] in (0, 1)
    assert (canes["precision"] is None) == (canes["frames_without_fit"] == 1)
    table = (out / "row_robustness.md").read_text()
    assert "| overcast | on | many | sparse |" in table
    png = (out / "row_robustness_map.png").read_bytes()
    assert png.startswith(b"\x89PNG") and len(png) > 10_000
    # Again: refused (it would mix two maps); with --resume nothing is left to run.
    assert main(args) == 2
    assert "--resume" in capsys.readouterr().err
    assert main([*args, "--resume"]) == 0
    assert "0 trials run in this process (0 failed), 1 already done" in capsys.readouterr().out
