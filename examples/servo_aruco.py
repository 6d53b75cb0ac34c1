"""Visual servoing of the gripper onto a berry tag with the two fused cameras (paper
section III-D, fig. 4 and fig. 10), in simulation.

The eye-to-hand camera tracks the marker cube (eq. 22) and finds the berry tag; the
gripper is placed in front of the berry, then the eye-in-hand camera takes over within
6 cm (eq. 21) and drives the grasp point onto the tag. No grasp. Prints the error as it
falls and saves the last eye-in-hand image with the tag's axes and the image centre, like
the paper's fig. 10.

    python examples/servo_aruco.py --seed 3 --out out/examples
"""

from __future__ import annotations

import sys

from softarm.commands._args import Parser, non_negative_int, output_dir


def main(argv: list[str] | None = None) -> int:
    ap = Parser(prog="servo_aruco.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=non_negative_int, default=3, help="seed of the bush and arm")
    ap.add_argument("--out", type=output_dir, default="out/examples", help="output folder")
    args = ap.parse_args(argv)

    import cv2
    import numpy as np

    from softarm.harvest import BerryTarget
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig
    from softarm.vision.detector import square_marker_poses

    rig = build_sim_rig(SimRigOptions(n_berries=1, seed=args.seed))
    berry = rig.bush.berries[0]
    result = rig.machine.run_berry(BerryTarget(berry.tag_id), grasp=False)
    print(f"berry tag {berry.tag_id} at {np.round(berry.position, 3)} m: {result.final_state}")
    steps = [r for r in rig.machine.log.records if r["kind"] == "step" and r["position_error_m"]]
    for r in steps[:: max(1, len(steps) // 15)] + steps[-1:]:
        print(
            f"  t = {r['t']:5.2f} s  {r['state']:<17} {r['camera']:<12} "
            f"error {1e3 * r['position_error_m']:7.2f} mm  pointing "
            f"{np.degrees(r['orientation_error_rad']):5.2f} deg"
        )
    print(
        f"final: measured {result.position_error_mm:.2f} mm, "
        f"true {result.true_position_error_mm:.2f} mm, "
        f"pointing {result.true_orientation_error_deg:.2f} deg"
    )
    vision = rig.vision
    img = cv2.cvtColor(vision.frame2(rig.clock.now()), cv2.COLOR_GRAY2BGR)
    h, w = img.shape[:2]
    cv2.circle(img, (w // 2, h // 2), 12, (0, 0, 255), 2)
    model = vision.model2
    for det in vision.detector.detect(img, model):
        if det.marker_id == berry.tag_id:
            pose = square_marker_poses(det.corners, model, vision.berry_tag)[0].T_camera_marker
            rvec, _ = cv2.Rodrigues(pose[:3, :3])
            cv2.drawFrameAxes(img, model.matrix, model.distortion, rvec, pose[:3, 3], 0.015)
    args.out.mkdir(parents=True, exist_ok=True)
    out = args.out / "servo_aruco.png"
    cv2.imwrite(str(out), img)
    print(f"saved {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
