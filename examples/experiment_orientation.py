"""IV-C: orientation control at 15 orientations from 0 to -150 deg about X, on the simulated arm.

Writes CSV, JSON and PNG files into the folder given as the first argument (default
`experiments-out`) and prints the summary. Add `--quick` for a short run.

    python examples/experiment_orientation.py out/ [--quick]
"""

import json
import sys
from pathlib import Path

from softarm.experiments import orientation


def main() -> None:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    out = Path(args[0]) if args else Path("experiments-out")
    summary = orientation.run(out, seed=0, quick="--quick" in sys.argv)
    print(json.dumps(summary, indent=2, default=str))


if __name__ == "__main__":
    main()
