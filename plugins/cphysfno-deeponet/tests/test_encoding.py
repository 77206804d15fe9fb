"""The branch's sensor readings and the trunk's time features against closed forms."""

from __future__ import annotations

import math

import pytest
import torch

from cphysfno_deeponet import fourier_features, relative_time, resample_to_sensors


@pytest.mark.parametrize(("steps", "sensors"), [(7, 30), (301, 16), (16, 16), (2, 5)])
def test_sensors_read_an_affine_function_exactly(steps: int, sensors: int) -> None:
    s = relative_time(steps, torch.float64, torch.device("cpu"))
    x = torch.stack([2.0 - 3.0 * s, 0.5 * s], dim=-1)[None]
    readings = resample_to_sensors(x, sensors)
    at = torch.linspace(0.0, 1.0, sensors, dtype=torch.float64)
    expected = torch.stack([2.0 - 3.0 * at, 0.5 * at])[None]
    assert readings.shape == (1, 2, sensors)
    torch.testing.assert_close(readings, expected, rtol=0, atol=1e-12)


def test_as_many_sensors_as_samples_reads_the_samples() -> None:
    x = torch.randn(3, 40, 2, dtype=torch.float64)
    torch.testing.assert_close(resample_to_sensors(x, 40), x.transpose(1, 2), rtol=0, atol=1e-14)


def test_sensors_interpolate_linearly_between_samples() -> None:
    x = torch.tensor([[[0.0], [1.0], [-1.0]]], dtype=torch.float64)
    readings = resample_to_sensors(x, 5)
    torch.testing.assert_close(readings[0, 0], torch.tensor([0.0, 0.5, 1.0, 0.0, -1.0]).double())


def test_one_sample_is_held() -> None:
    readings = resample_to_sensors(torch.tensor([[[1.5, -2.0]]]), 4)
    assert torch.equal(readings, torch.tensor([[[1.5] * 4, [-2.0] * 4]]))


def test_relative_time_spans_the_record() -> None:
    assert torch.equal(
        relative_time(5, torch.float32, torch.device("cpu")), torch.tensor([0, 0.25, 0.5, 0.75, 1])
    )
    assert torch.equal(relative_time(1, torch.float32, torch.device("cpu")), torch.tensor([0.0]))


def test_fourier_features_closed_form() -> None:
    s = torch.tensor([0.0, 0.3, 1.0], dtype=torch.float64)
    features = fourier_features(s, 3)
    assert features.shape == (3, 7)
    for row, value in enumerate(s.tolist()):
        expected = [value]
        expected += [math.cos(math.pi * k * value) for k in (1, 2, 3)]
        expected += [math.sin(math.pi * k * value) for k in (1, 2, 3)]
        torch.testing.assert_close(features[row], torch.tensor(expected).double())
    torch.testing.assert_close(fourier_features(s, 0), s[:, None])
