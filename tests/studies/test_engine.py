"""The Dask engine: a seeded study gives exactly the same numbers in this process, in other chunks, and on a
two-worker dask.distributed cluster on 127.0.0.1 (started and shut down by the test)."""

from __future__ import annotations

import numpy as np
import pytest

from linkwork.errors import LinkworkError
from linkwork.studies.engine import map_chunks, scheduler_address
from linkwork.studies.imperfections import ImperfectionModel
from linkwork.studies.robustness import robustness
from linkwork.studies.study_file import load_study
from linkwork.studies.sweep import run_sweep


def _same(a, b) -> None:
    np.testing.assert_array_equal(a.misfit_max, b.misfit_max)
    np.testing.assert_array_equal(a.first_order_max, b.first_order_max)
    np.testing.assert_array_equal(a.mobility_kept, b.mobility_kept)
    np.testing.assert_array_equal(a.hist, b.hist)
    np.testing.assert_array_equal(a.drive_max, b.drive_max)


def test_chunking_does_not_change_any_sample(bennett):
    mech, path = bennett
    model = ImperfectionModel(1e-4, np.radians(0.01), distribution="uniform")
    whole = robustness(mech, path, model, 60, seed=9, workers=0)
    pieces = robustness(mech, path, model, 60, seed=9, workers=0, chunk=7)
    _same(whole, pieces)
    other = robustness(mech, path, model, 60, seed=10, workers=0)
    assert not np.array_equal(other.misfit_max, whole.misfit_max)


@pytest.fixture
def port_8787_taken():
    """Dask's default HTTP port held (when free) by a listening socket, as another cluster or a notebook would."""
    import socket

    holder = socket.socket()
    try:
        holder.bind(("127.0.0.1", 8787))
        holder.listen(1)
    except OSError:  # already taken by something else: the same situation
        pass
    yield
    holder.close()


def test_two_worker_cluster_gives_the_local_numbers(bennett, tmp_path, port_8787_taken):
    """The engine's own local cluster (as the command line starts it): the numbers of this process exactly, its
    settings in every worker, and no dask warning (pytest runs with -W error) when port 8787 is taken."""
    import dask

    from linkwork.studies.engine import LOCAL_CLUSTER_CONFIG, dask_client

    mech, path = bennett
    model = ImperfectionModel(1e-4, np.radians(0.01))
    local = robustness(mech, path, model, 80, seed=3, workers=0)
    study_file = tmp_path / "study.toml"
    study_file.write_text(
        'linkage = "bennett"\n[trace]\nuntil = "A=90"\nsteps = 8\n[grid]\nalpha1 = [30, 40, 50]\n'
        "[robustness]\nsamples = 20\nhinge_position_tol = 1e-4\nhinge_direction_tol = 0.01\n",
        encoding="utf-8",
    )
    study = load_study(study_file)
    local_rows = [row for row, _ in run_sweep(study, workers=0)]
    seen: list[tuple[int, int]] = []
    with dask_client(None, 2) as client:
        settings = client.run(lambda: {key: dask.config.get(key) for key in LOCAL_CLUSTER_CONFIG})
        assert list(settings.values()) == [LOCAL_CLUSTER_CONFIG] * 2
        remote = robustness(
            mech, path, model, 80, seed=3, client=client, chunk=20, progress=lambda d, t: seen.append((d, t))
        )
        remote_rows = [row for row, _ in run_sweep(study, client=client)]
    _same(local, remote)
    assert remote_rows == local_rows  # every number of every grid point, exactly
    assert seen[-1] == (4, 4)


def test_results_come_back_in_chunk_order_in_process():
    out = list(map_chunks(lambda shared, a, b: shared + a * b, 1, [(1, 2), (3, 4), (5, 6)], workers=0))
    assert out == [3, 13, 31]


def test_scheduler_address_from_the_environment(monkeypatch):
    monkeypatch.setenv("LINKWORK_SCHEDULER", "tcp://10.0.0.1:8786")
    assert scheduler_address(None) == "tcp://10.0.0.1:8786"
    assert scheduler_address("tcp://127.0.0.1:1") == "tcp://127.0.0.1:1"
    monkeypatch.delenv("LINKWORK_SCHEDULER")
    assert scheduler_address(None) is None
    with pytest.raises(LinkworkError):
        scheduler_address("nonsense")


def test_a_samples_seed_reproduces_it_alone(bennett):
    from linkwork.studies.imperfections import hinge_errors, perturbed_twists
    from linkwork.studies.misfit import misfit_batch
    from linkwork.studies.robustness import MAX_ITER, prepare, run_chunk

    mech, path = bennett
    setup = prepare(mech, path, ImperfectionModel(1e-4, np.radians(0.01)), seed=12)
    chunk = run_chunk(setup, 30, 40)
    seed = chunk.seed[7:8]  # sample 37, as samples.parquet records it
    twists = perturbed_twists(hinge_errors(seed, setup.mech, setup.model, setup.lines), setup.lines)
    alone = misfit_batch(twists, *setup.kernel_args(), MAX_ITER)
    assert alone.max() == chunk.misfit_max[7]
