"""IV-B: position control at 35 set-points along +Y, proposed (eq. 13) against
conventional resolved rate (eq. 7), on the simulated arm.

Writes CSV, JSON and PNG files into the folder given as the first argument (default
`experiments-out`) and prints the summary. Add `--quick` for a short run.

    python examples/experiment_position.py out/ [--quick]
"""

import json
import sys
from pathlib import Path

from softarm.experiments import position


def main() -> None:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    out = Path(args[0]) if args else Path("experiments-out")
    summary = position.run(out, seed=0, quick="--quick" in sys.argv)
    print(json.dumps(summary, indent=2, default=str))


if __name__ == "__main__":
    main()
