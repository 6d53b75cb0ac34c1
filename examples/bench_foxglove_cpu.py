"""The CPU the Foxglove live view's thread takes, against the control loop's own.

    MUJOCO_GL=egl python examples/bench_foxglove_cpu.py [--runs N] [--records-only]

Each run is the benchmark's harvest (tests/benchmarks/test_foxglove_bench.py: the tag
world, seed 90030, two berries) with the view serving a client process that reads every
topic, pinned to CPU 1 as an app on another computer would be. The loop's CPU time is
its thread's (``time.thread_time``), the view's is its thread's from
``/proc/self/task/TID/stat`` (Linux; 10 ms ticks): a share of CPU, which the machine's
other load does not change as it changes wall time. The view's thread holds Python's
lock while it builds messages, not while OpenCV encodes a JPEG (which releases it), so
with ``--records-only`` (no camera frames) the share is what the loop can lose to it on
a machine with a core to spare; with the frames, what the view adds in all.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections import deque
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1] / "tests"


def thread_cpu(tid: int) -> float:
    """CPU seconds (user + system) of this process's thread ``tid``."""
    fields = Path(f"/proc/self/task/{tid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def one_run(records_only: bool) -> tuple[float, float, float]:
    """(wall s, loop CPU s, view thread CPU s) of one served harvest."""
    sys.path[:0] = [str(TESTS / "benchmarks"), str(TESTS)]
    from test_foxglove_bench import Served

    served = Served(view=True)
    live = served.live
    assert live is not None
    if records_only:
        live._images = deque(maxlen=0)  # frames handed over are dropped, none encoded
    view_tid = live._thread.native_id
    assert view_tid is not None
    view0, loop0, wall0 = thread_cpu(view_tid), time.thread_time(), time.perf_counter()
    served.rig.run()
    wall, loop = time.perf_counter() - wall0, time.thread_time() - loop0
    view = thread_cpu(view_tid) - view0
    served.close()
    return wall, loop, view


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--records-only", action="store_true", help="no camera frames sent")
    args = parser.parse_args()
    os.environ.setdefault("FOXGLOVE_CLIENT_CPU", "1")
    shares = []
    for _ in range(args.runs):
        wall, loop, view = one_run(args.records_only)
        shares.append(view / loop)
        print(f"wall {wall:.2f} s, loop CPU {loop:.2f} s, view thread CPU {view:.3f} s "
              f"({100 * view / loop:.1f} % of the loop's)", flush=True)  # fmt: skip
    shares.sort()
    print(f"median share {100 * shares[len(shares) // 2]:.1f} % over {len(shares)} runs")


if __name__ == "__main__":
    main()
