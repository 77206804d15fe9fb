"""Records analysed in worker processes: order, recycling, collapses, crashes, bugs and
what the analyses print."""

from __future__ import annotations

import functools
import importlib
import logging
import sys
import textwrap

import numpy as np
import pytest
from cphysfno_opensees.runner import run_records

from cphysfno_core import InputError, PluginError

ANALYSES = '''
"""Analyses for the runner tests (a module, so that spawned workers can import them)."""

import os
import signal
import sys

import numpy as np

from cphysfno_opensees.transient import AnalysisFailed


def scaled(ag, dt, gain):
    """[T, 2]: the record times gain, and the worker's process id."""
    return np.stack([gain * ag, np.full(ag.shape, float(os.getpid()))], axis=1)


def scaled_once(ag, dt):
    """[T, 2]: the record itself, and the worker's process id."""
    return scaled(ag, dt, 1.0)


def fails_on_negative_start(ag, dt):
    """Does not converge at step 7 where the record starts below zero."""
    if ag[0] < 0:
        raise AnalysisFailed(dt * 7, "everything", scaled(ag, dt, 1.0)[:7])
    return scaled(ag, dt, 1.0)


def fails_without_history(ag, dt):
    """Does not converge, and knows nothing of the steps before."""
    raise AnalysisFailed(0.0, "everything")


def talks(ag, dt):
    """Prints as OpenSees does: a warning on stderr for every record, a count on stdout
    for a record that starts below zero."""
    print('WARNING: DO NOT USE THE "Bilin" MATERIAL', file=sys.stderr)
    if ag[0] < 0:
        print(f"failed to converge after: {int(10 + 10 * ag[1] ** 2)} iterations")
    return scaled(ag, dt, 1.0)


def crashes_on_negative_start(ag, dt):
    """Kills its own process, as a segmentation fault in OpenSees would."""
    if ag[0] < 0:
        os.kill(os.getpid(), signal.SIGSEGV)
    return scaled(ag, dt, 1.0)


def buggy(ag, dt):
    """A programming error."""
    return undefined_name  # noqa: F821


def wrong_shape(ag, dt):
    """Returns one output too few."""
    return ag[:, None]
'''


@pytest.fixture(scope="module")
def analyses(tmp_path_factory):
    folder = tmp_path_factory.mktemp("analyses")
    (folder / "runner_analyses.py").write_text(textwrap.dedent(ANALYSES))
    sys.path.insert(0, str(folder))  # spawned workers start with the parent's sys.path
    try:
        yield importlib.import_module("runner_analyses")
    finally:
        sys.path.remove(str(folder))
        sys.modules.pop("runner_analyses", None)


@pytest.fixture(scope="module")
def records() -> np.ndarray:
    rng = np.random.default_rng(3)
    ag = rng.standard_normal((7, 50))
    ag[:, 0] = [1.0, -1.0, 1.0, 1.0, -1.0, 1.0, 1.0]
    return ag


def test_every_record_lands_in_its_row_and_workers_are_recycled(analyses, records):
    analyse = functools.partial(analyses.scaled, gain=2.0)
    runs = run_records(analyse, records, 0.01, 2, workers=2, records_per_worker=2)
    u = runs.displacement
    assert runs.failures == {} and not runs.collapsed.any() and runs.messages == {}
    assert u.shape == (7, 50, 2) and u.dtype == np.float64
    np.testing.assert_array_equal(u[:, :, 0], 2.0 * records)
    pids = u[:, 0, 1]
    assert len(set(pids)) >= 4  # 7 records, at most 2 per process
    assert max(np.sum(pids == pid) for pid in set(pids)) <= 2


def test_records_that_do_not_converge_collapsed_with_their_history_until_then(analyses, records):
    runs = run_records(analyses.fails_on_negative_start, records, 0.01, 2, workers=2)
    u = runs.displacement
    assert runs.failures == {}
    assert np.flatnonzero(runs.collapsed).tolist() == [1, 4]
    assert runs.collapse_causes[1] == "did not converge at t = 0.07 s after everything"
    np.testing.assert_array_equal(u[[1, 4], :7, 0], records[[1, 4], :7])
    assert np.isnan(u[[1, 4], 7:]).all()
    np.testing.assert_array_equal(u[[0, 2, 3, 5, 6], :, 0], records[[0, 2, 3, 5, 6]])


def test_a_collapse_without_history_is_nan_throughout(analyses, records):
    runs = run_records(analyses.fails_without_history, records[:2], 0.01, 2)
    assert runs.collapsed.all() and np.isnan(runs.displacement).all()


def test_what_an_analysis_prints_comes_back_by_record(analyses, records, capfd):
    runs = run_records(analyses.talks, records, 0.01, 2, workers=2, records_per_worker=3)
    assert sorted(runs.messages) == list(range(7))
    assert runs.messages[0] == 'WARNING: DO NOT USE THE "Bilin" MATERIAL\n'
    for i in (1, 4):
        count = int(10 + 10 * records[i, 1] ** 2)
        assert runs.messages[i] == (
            'WARNING: DO NOT USE THE "Bilin" MATERIAL\n'
            f"failed to converge after: {count} iterations\n"
        )
    shown = capfd.readouterr()
    assert "Bilin" not in shown.out + shown.err


def test_a_worker_that_dies_fails_its_record_and_the_rest_go_on(analyses, records):
    runs = run_records(analyses.crashes_on_negative_start, records, 0.01, 2, workers=2)
    u, failures = runs.displacement, runs.failures
    assert set(failures) == {1, 4} and not runs.collapsed.any()
    assert "SIGSEGV" in failures[4] and "died" in failures[4]
    assert np.isnan(u[[1, 4]]).all()
    np.testing.assert_array_equal(u[[0, 2, 3, 5, 6], :, 0], records[[0, 2, 3, 5, 6]])


def test_a_bug_in_the_analysis_is_raised_with_its_traceback(analyses, records):
    with pytest.raises(PluginError, match="NameError: name 'undefined_name'"):
        run_records(analyses.buggy, records[:2], 0.01, 2)


def test_a_wrong_shape_is_a_plugin_error(analyses, records):
    with pytest.raises(PluginError, match=r"shape \(50, 1\), expected \(50, 2\)"):
        run_records(analyses.wrong_shape, records[:1], 0.01, 2)


def test_progress_is_logged(analyses, records, caplog):
    with caplog.at_level(logging.INFO, logger="cphysfno_opensees.runner"):
        analyse = functools.partial(analyses.scaled, gain=1.0)
        run_records(analyse, records[:2], 0.01, 2, description="test set")
    assert "test set: 2/2 records (0 collapsed, 0 failed)" in caplog.text


@pytest.mark.parametrize(
    "arguments",
    [
        {"acceleration": np.zeros(5)},
        {"workers": 0},
        {"records_per_worker": 0},
    ],
)
def test_bad_arguments_are_input_errors(analyses, records, arguments):
    call = {"acceleration": records, "workers": 1, "records_per_worker": 1, **arguments}
    with pytest.raises(InputError):
        run_records(functools.partial(analyses.scaled, gain=1.0), dt=0.01, n_outputs=2, **call)


def _run_in_daemon(analyse, records, queue):
    try:
        run_records(analyse, records, 0.01, 2)
        queue.put("ran")
    except PluginError as error:
        queue.put(str(error))


def test_a_daemonic_process_is_told_how_to_configure_its_workers(analyses, records):
    import multiprocessing

    context = multiprocessing.get_context("spawn")
    queue = context.Queue()
    process = context.Process(
        target=_run_in_daemon, args=(analyses.scaled_once, records, queue), daemon=True
    )
    process.start()
    message = queue.get(timeout=120)
    process.join(timeout=30)
    assert "distributed.worker.daemon = False" in message


def test_records_run_inside_dask_workers_of_the_local_cluster(analyses, records):
    from cphysfno_core.config import DataConfig
    from cphysfno_core.data.executors import _dask_client

    settings = DataConfig(executor="dask", workers=1)
    with _dask_client(settings) as client:
        run = functools.partial(run_records, workers=2)  # submit() takes workers itself
        runs = client.submit(run, analyses.scaled_once, records, 0.01, 2).result(300)
    assert runs.failures == {}
    np.testing.assert_array_equal(runs.displacement[:, :, 0], records)
