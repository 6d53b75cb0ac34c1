"""Sweeps and tuning on a Ray cluster started in the test with Ray's own
``ray.cluster_utils.Cluster`` (a head and a worker node): joining by address, resume after
a partial table, a worker that dies, a tuning run. The trials are fakes (tests/sweep/fakes)
so that each test takes seconds; the real trial runs in test_local."""

from __future__ import annotations

import sys
import tomllib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("ray")
pytest.importorskip("pyarrow")
import pyarrow.parquet as pq
import ray
from ray.cluster_utils import Cluster

import softarm
from softarm.sweep import parse_spec
from softarm.sweep.runner import run_sweep

from . import fakes

# The workers cannot import the tests package: send the fakes by value.
ray.cloudpickle.register_pickle_by_value(sys.modules[fakes.__name__])


def _spec(seeds: list[int], **extra: Any) -> Any:
    doc = {"sweep": {"seeds": seeds, "berries": 2, "plant": {"hysteresis_psi": [1.5, 5.0]}}}
    return parse_spec({**doc, **extra})


@pytest.fixture(scope="module")
def cluster() -> Iterator[Cluster]:
    c = Cluster(initialize_head=True, head_node_args={"num_cpus": 1})
    c.add_node(num_cpus=1)
    c.wait_for_nodes()
    try:
        yield c
    finally:
        c.shutdown()


@pytest.fixture
def joined(cluster: Cluster) -> Iterator[str]:
    """The cluster's address; the sweep under test connects and disconnects itself."""
    yield cluster.address
    if ray.is_initialized():
        ray.shutdown()


def test_sweep_joins_a_cluster_by_address(joined: str, tmp_path: Path) -> None:
    spec = _spec([0, 1])
    outcome = run_sweep(spec, tmp_path, address=joined, trial_fn=fakes.quick, progress=False)
    assert (outcome.ran, outcome.failed, outcome.cpus) == (4, 0, 2.0)
    assert not ray.is_initialized()  # the sweep disconnected from the cluster
    rows = pq.read_table(tmp_path / "results.parquet").to_pylist()
    assert len(rows) == 4 * 2
    assert {(r["hysteresis_psi"], r["seed"]) for r in rows} == {
        (1.5, 0), (1.5, 1), (5.0, 0), (5.0, 1)
    }  # fmt: skip


def test_resume_after_a_partial_table(joined: str, tmp_path: Path) -> None:
    spec = _spec([0, 1, 2])
    first = run_sweep(spec, tmp_path, address=joined, trial_fn=fakes.quick, progress=False)
    assert first.ran == 6
    # Keep a partial table only (as left by a sweep stopped half way), without its parts.
    full = pq.read_table(tmp_path / "results.parquet")
    keep = [t.trial_id for t in spec.trials()[:4]]
    partial = full.take([i for i, t in enumerate(full.column("trial_id").to_pylist()) if t in keep])
    for p in (tmp_path / "parts").iterdir():
        p.unlink()
    pq.write_table(partial, tmp_path / "results.parquet")

    ran: list[str] = []
    again = run_sweep(spec, tmp_path, address=joined, trial_fn=fakes.quick, progress=False,
                      resume=True, on_trial=lambda t, rows: ran.append(t.trial_id))  # fmt: skip
    assert (again.skipped, again.ran) == (4, 2)
    assert sorted(ran) == sorted(t.trial_id for t in spec.trials()[4:])
    rows = pq.read_table(tmp_path / "results.parquet").to_pylist()
    assert len(rows) == 6 * 2 and len({r["trial_id"] for r in rows}) == 6


def test_a_dying_worker_fails_its_trial_only(joined: str, tmp_path: Path) -> None:
    spec = _spec([0, 1])
    outcome = run_sweep(spec, tmp_path, address=joined, trial_fn=fakes.crash_on_seed_1,
                        progress=False, max_retries=1)  # fmt: skip
    assert (outcome.ran, outcome.failed) == (4, 2)  # seed 1 of both plant points
    rows = pq.read_table(tmp_path / "results.parquet").to_pylist()
    failed = [r for r in rows if r["error"] is not None]
    assert {r["seed"] for r in failed} == {1} and len(failed) == 2
    assert all("Worker" in r["error"] or "died" in r["error"] for r in failed), failed
    assert len(rows) - len(failed) == 2 * 2  # seed 0's berries all there

    # --resume runs the failed trials again (here a worker that no longer dies).
    again = run_sweep(spec, tmp_path, address=joined, trial_fn=fakes.quick, progress=False,
                      resume=True)  # fmt: skip
    assert (again.skipped, again.ran, again.failed) == (2, 2, 0)
    rows = pq.read_table(tmp_path / "results.parquet").to_pylist()
    assert len(rows) == 4 * 2 and all(r["error"] is None for r in rows)


def test_a_worker_killed_once_is_retried(joined: str, tmp_path: Path) -> None:
    spec = _spec([7])
    for t in spec.trials():
        fakes.crash_marker(t).unlink(missing_ok=True)
    try:
        outcome = run_sweep(spec, tmp_path, address=joined, trial_fn=fakes.crash_once,
                            progress=False, max_retries=1)  # fmt: skip
        assert all(fakes.crash_marker(t).exists() for t in spec.trials())  # each one died
    finally:
        for t in spec.trials():
            fakes.crash_marker(t).unlink(missing_ok=True)
    assert (outcome.ran, outcome.failed) == (2, 0)
    rows = pq.read_table(tmp_path / "results.parquet").to_pylist()
    assert len(rows) == 2 * 2 and all(r["error"] is None for r in rows)


def test_tune_writes_gains_that_harvest_and_gains_load(joined: str, tmp_path: Path) -> None:
    pytest.importorskip("optuna")
    from softarm.sweep.gains_file import load_gains
    from softarm.sweep.tune import run_tune

    space = {"hybrid_alpha": {"low": 0.05, "high": 0.6, "log": True}}
    spec = _spec([0], tune={"samples": 3, "seed": 1, "space": space})
    out = tmp_path / "gains.toml"
    outcome = run_tune(spec, out, address=joined, trial_fn=fakes.quick, progress=False)
    assert len(outcome.candidates) == 3
    # The search starts from the current gains, so the default alpha was evaluated.
    assert outcome.baseline is not None and outcome.baseline["hybrid_alpha"] == 0.3
    assert outcome.metrics["success"] == 1.0
    with out.open("rb") as f:
        gains = softarm.Gains(**tomllib.load(f)["gains"])
    assert gains.hybrid_alpha == outcome.gains["hybrid_alpha"]
    assert 0.05 <= gains.hybrid_alpha <= 0.6
    assert load_gains(out)["hybrid_alpha"] == gains.hybrid_alpha


def test_tune_reports_each_trial_of_a_candidate(
    joined: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The bar moves per trial (2 plant points here), not per candidate."""
    pytest.importorskip("optuna")
    import softarm.sweep.tune as tune_module

    bars: list[Any] = []

    def keep(*args: Any, **kwargs: Any) -> Any:
        bars.append(real(*args, **kwargs))
        return bars[-1]

    real = tune_module._bar_callback
    monkeypatch.setattr(tune_module, "_bar_callback", keep)
    spec = _spec([0], tune={"samples": 2, "seed": 1})
    out = tmp_path / "gains.toml"
    tune_module.run_tune(spec, out, address=joined, trial_fn=fakes.quick, progress=False)
    (bar,) = bars
    assert bar.reports == 2 * 2 and bar.count == 2 * 2 and bar.finished == 2
