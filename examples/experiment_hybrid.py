"""IV-D: hybrid position and orientation control at 7 poses, with and without joint-limit
avoidance, on the simulated arm.

Writes CSV, JSON and PNG files into --out and prints the summary (floats rounded).

    python examples/experiment_hybrid.py --out out/experiments --quick
"""

from __future__ import annotations

import json
import sys

from softarm.commands._args import Parser, non_negative_int, output_dir
from softarm.formatting import rounded


def main(argv: list[str] | None = None) -> int:
    parser = Parser(prog="experiment_hybrid.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=output_dir, default="out/experiments", help="output folder")
    parser.add_argument(
        "--seed", type=non_negative_int, default=0, help="seed of the simulated arm"
    )
    parser.add_argument("--quick", action="store_true", help="fewer targets, shorter runs")
    args = parser.parse_args(argv)

    from softarm.experiments import hybrid

    summary = hybrid.run(args.out, seed=args.seed, quick=args.quick)
    print(json.dumps(rounded(summary), indent=2, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())
