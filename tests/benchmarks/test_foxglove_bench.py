"""The Foxglove live view's cost to the control loop: the simulated harvest of two
tag-world berries (seed 90030, of the range reserved for CI), timed without the view and
with the view (the cameras' frames too) serving a client that subscribes to every topic
and reads all it is sent (the rig, the server and the client set up untimed). The
simulated loop runs as fast as it can, so its wall time is what its steps cost (the same
steps in both: the same seed); the view's thread and the SDK's must leave it unchanged
within 5 % (BENCHMARKS.md, "The Foxglove live view")."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from softarm.harvest.rigs.sim.options import SimRigOptions
from softarm.harvest.rigs.sim.rig import SimRig, build_sim_rig

pytest.importorskip("foxglove")
pytest.importorskip("websockets")
from softarm.viz.foxglove_live import LiveView

SEED = 90030


#: The client, in a process of its own as a Foxglove app is: subscribes to every topic
#: and reads until the server closes.
CLIENT = """
import sys
sys.path.insert(0, sys.argv[2])
from test_newcomer_foxglove import TOPICS, Client
client = Client(sys.argv[1])
client.subscribe(TOPICS)
print("subscribed", flush=True)
frames = 0
while True:
    try:
        frame = client.ws.recv(timeout=30)
    except Exception:
        break
    frames += isinstance(frame, bytes)
print(frames, flush=True)
"""


def _client_cpus() -> None:
    """With ``FOXGLOVE_CLIENT_CPU=N``, the client process runs on CPU N only: a Foxglove
    app on another computer does not take the robot's cores, and on a 2-vCPU machine an
    unpinned client competes with the loop for them (BENCHMARKS.md)."""
    cpu = os.environ.get("FOXGLOVE_CLIENT_CPU")
    if cpu is not None:
        os.sched_setaffinity(0, {int(cpu)})


class Served:
    """A rig, and with ``view`` the live view of its log and a client process reading it."""

    def __init__(self, view: bool) -> None:
        self.rig: SimRig = build_sim_rig(SimRigOptions(n_berries=2, seed=SEED))
        self.live: LiveView | None = None
        self.client: subprocess.Popen[str] | None = None
        if view:
            self.live = LiveView(self.rig.machine.log.records, "127.0.0.1:0")
            self.live.attach_cameras(self.rig.vision)  # as `harvest --foxglove` does
            tests = str(Path(__file__).parents[1])
            self.client = subprocess.Popen(
                [sys.executable, "-c", CLIENT, self.live.url, tests],
                stdout=subprocess.PIPE, text=True, preexec_fn=_client_cpus,
            )  # fmt: skip
            assert self.client.stdout is not None
            assert self.client.stdout.readline().strip() == "subscribed"
            time.sleep(0.3)  # the server takes the subscription in

    def close(self) -> int:
        """Stop the view; the frames the client received (0 without one)."""
        if self.live is None or self.client is None:
            return 0
        self.live.close()
        out = self.client.communicate(timeout=60)[0]
        return int(out.split()[-1])


def _bench(benchmark: Any, view: bool) -> None:
    served: list[Served] = []

    def setup() -> tuple[tuple[Any, ...], dict[str, Any]]:
        served.append(Served(view))
        return (served[-1].rig,), {}

    def harvest(rig: SimRig) -> None:
        assert rig.run().berries

    benchmark.pedantic(
        harvest, setup=setup, rounds=int(os.environ.get("FOXGLOVE_BENCH_ROUNDS", "3")), iterations=1
    )
    for s in served:
        frames = s.close()
        assert not view or frames > 0, "the client received nothing"


def test_harvest_without_the_view(benchmark: Any) -> None:
    _bench(benchmark, view=False)


def test_harvest_with_a_foxglove_client(benchmark: Any) -> None:
    _bench(benchmark, view=True)
