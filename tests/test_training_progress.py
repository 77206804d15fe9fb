"""Training progress: one line per epoch with the time left."""

import pytest
from toy_training import fit_toy, toy_data

from cphysfno_core.model import training


class TenSecondClock:
    """Stands in for ``time`` in the trainer: every reading is 10 s after the one before."""

    def __init__(self):
        self.now = 0.0

    def perf_counter(self) -> float:
        self.now += 10.0
        return self.now


def test_time_left_is_the_mean_epoch_time_times_the_epochs_left(toy_registry, monkeypatch):
    # readings: start, then per epoch its start and its end, so 20 s per epoch on average
    monkeypatch.setattr(training, "time", TenSecondClock())
    reports = []
    fit_toy(*toy_data(), progress=reports.append)
    assert [r.epoch for r in reports] == [1, 2, 3, 4, 5, 6]
    assert [r.seconds for r in reports] == [10.0] * 6
    assert [r.seconds_left for r in reports] == [100.0, 80.0, 60.0, 40.0, 20.0, 0.0]


@pytest.mark.parametrize(
    ("epoch", "best", "seconds_left", "ending"),
    [
        (3, False, 40.0, "12.3s    about 40 s left"),
        (3, True, 750.0, "12.3s *  about 12 min left"),
        (3, False, 5760.0, "12.3s    about 1.6 h left"),
        (6, False, 0.0, "12.3s"),
        (6, True, 0.0, "12.3s *"),
    ],
)
def test_each_epoch_line_ends_with_the_time_left(capsys, epoch, best, seconds_left, ending):
    report = training.EpochReport(epoch, 6, 0.5, 0.6, 1e-3, 12.3, best, seconds_left)
    training.print_progress(report)
    line = capsys.readouterr().err.rstrip("\n")
    assert line.startswith(f"  epoch    {epoch}/6  train 0.5000  val 0.6000  lr 1.00e-03  12.3s")
    assert line.endswith(ending)
