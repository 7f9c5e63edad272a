"""Clusters kept for a block (:mod:`workbench.distributed.kept`): inside the block equal
arguments share one running cluster, other arguments get their own, and everything is closed
when the block ends; an experiment's untimed tiny run and its timed run draw on the same
workers. Real LocalClusters of one worker process, no mocks."""

import os

import pytest

from workbench.distributed.cluster import sweep_cluster
from workbench.distributed.kept import innermost_kept, kept_clusters
from workbench.experiment.registry import EXPERIMENTS, experiment, run_experiment

PIDS: list[tuple[str, int]] = []


def _worker_pid(cluster) -> int:
    (pid,) = cluster.client.run(os.getpid).values()
    return pid


@pytest.mark.slow
def test_a_kept_block_shares_one_cluster_per_arguments_and_closes_them_at_its_end():
    with sweep_cluster(1, gl=False) as first:
        alone = (first.address, _worker_pid(first))
    with kept_clusters() as block:
        assert innermost_kept() is block
        with sweep_cluster(1, gl=False) as a:
            pid = _worker_pid(a)
        with sweep_cluster(1, gl=False) as b:  # the same cluster, still running
            assert (b.address, _worker_pid(b)) == (a.address, pid)
        with sweep_cluster(1, gl=False, raster_threads=1) as other:  # other arguments
            assert other.address != a.address
        clients = [c.client for c in block.clusters.values()]
        assert len(clients) == 2 and all(c.status == "running" for c in clients)
    assert innermost_kept() is None and all(c.status == "closed" for c in clients)
    assert (a.address, pid) != alone  # outside a block each call starts its own


@pytest.mark.slow
def test_an_experiments_warm_up_and_timed_run_share_their_workers(tmp_path):
    def probe(exp):
        with sweep_cluster(1, gl=False) as cluster:
            PIDS.append((exp.size, _worker_pid(cluster)))
        return [{"size": exp.size}]

    experiment("kept_probe", "records the pid of its cluster's worker")(probe)
    try:
        PIDS.clear()
        run_experiment("kept_probe", tmp_path, size="quick")
        run_experiment("kept_probe", tmp_path, size="quick")
    finally:
        EXPERIMENTS.pop("kept_probe", None)
    (tiny, a), (quick, b), (tiny2, c), (quick2, d) = PIDS
    assert (tiny, quick, tiny2, quick2) == ("tiny", "quick", "tiny", "quick")
    assert a == b and c == d and a != c  # one cluster per run of the experiment
