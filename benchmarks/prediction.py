"""Prediction speed and memory of ``CompositeModel.predict`` end to end: ELS -> FNO -> refiner.

The paper's Example 3 (nine-story frame, 300 test records of 4001 samples at 0.005 s) says
the trained C-PhysFNO predicts all test records in under 5 s on a GPU. Here the same sizes
run on this machine's CPU: the ELS of a nine-DOF linear shear building (a stand-in for the
frame's elastic model, first period 2.27 s as the paper's frame), an FNO of 8 layers, 40
modes, width 128 and projection 128 -> 9 (the paper: lifting and projection as in Example 1,
whose projection is 128 wide), and the linear-regression refiner. Nothing is trained: the
operator keeps its random initial weights and the refiner is fitted on random data, which
changes no timing. A second measurement predicts Example 1 records, each count in a fresh
process, and reports the peak resident memory beside the size of the returned arrays.
"""

from __future__ import annotations

import multiprocessing
import time
from functools import partial

import numpy as np
import torch
from cphysfno_fno import FNO1d
from cphysfno_physics.linear_response import linear_response
from pydantic import Field
from scipy.linalg import eigh

import cphysfno_core as cp
from cphysfno_core import plugin
from cphysfno_core.model import composite
from cphysfno_core.model.training import Normalizer, TrainingHistory, describe_device
from cphysfno_core.plugin import LinearSystem, Structure

from .common import Row, best_time
from .training import best_matmul_rate

EXAMPLE3_OPERATOR = {"layers": 8, "modes": 40, "width": 128, "projection_width": 128}
EXAMPLE1_OPERATOR = {"layers": 6, "modes": 32, "width": 64, "projection_width": 128}
EXAMPLE1_STIFFNESS = (7.5e7, 7.0e7, 6.0e7, 4.5e7, 2.5e7)


class LinearShearBuilding(Structure):
    """A linear shear building with classical damping, for benchmarks of the ELS path.

    Floors ``1..n`` carry the mass ``floor_mass_kg``; story ``i`` (between floors ``i - 1``
    and ``i``, floor 0 being the ground) has the stiffness ``story_stiffness_n_per_m[i - 1]``.
    Damping is ``damping_ratio`` in every mode. Outputs are the floor displacements relative
    to the ground (m); :meth:`simulate` returns the exact linear response.
    """

    name = "benchmark-linear-shear-building"
    capabilities = frozenset({"linear_system"})

    class Params(plugin.Params):
        floor_mass_kg: float = Field(3.0e4, gt=0)
        story_stiffness_n_per_m: tuple[float, ...] = EXAMPLE1_STIFFNESS
        damping_ratio: float = Field(0.05, ge=0, lt=1)

    @property
    def output_names(self) -> tuple[str, ...]:
        return tuple(f"floor-{i + 1}" for i in range(len(self.params.story_stiffness_n_per_m)))

    def _mass_stiffness(self) -> tuple[np.ndarray, np.ndarray]:
        k = np.asarray(self.params.story_stiffness_n_per_m)
        n = k.size
        stiffness = np.diag(k + np.append(k[1:], 0.0))
        stiffness -= np.diag(k[1:], 1) + np.diag(k[1:], -1)
        return np.eye(n) * self.params.floor_mass_kg, stiffness

    def linear_system(self) -> LinearSystem:
        mass, stiffness = self._mass_stiffness()
        omega2, shapes = eigh(stiffness, mass)
        modal = np.diag(2.0 * self.params.damping_ratio * np.sqrt(omega2))
        damping = mass @ shapes @ modal @ shapes.T @ mass
        n = mass.shape[0]
        return LinearSystem(mass, damping, stiffness, np.ones(n), np.eye(n))

    def periods(self, n: int | None = None) -> np.ndarray:
        omega2 = eigh(*reversed(self._mass_stiffness()), eigvals_only=True)
        return (2.0 * np.pi / np.sqrt(omega2))[:n]

    def simulate(self, motions: cp.GroundMotions, *, dt: float | None = None) -> cp.Responses:
        if dt is not None:
            raise self.missing("coarse_simulation", "simulate(dt=...)")
        u = linear_response(self.linear_system(), motions.acceleration, motions.dt)
        return cp.Responses(u, motions.dt)


def example3_structure(stories: int = 9, period_s: float = 2.27) -> LinearShearBuilding:
    """Uniform shear building of ``stories`` floors of 1e6 kg with first period ``period_s``.

    A uniform shear building has ``omega_1 = 2 sqrt(k / m) sin(pi / (2 (2 n + 1)))``.
    """
    mass = 1.0e6
    omega = 2.0 * np.pi / period_s
    k = mass * (omega / (2.0 * np.sin(np.pi / (2 * (2 * stories + 1))))) ** 2
    return LinearShearBuilding(floor_mass_kg=mass, story_stiffness_n_per_m=(k,) * stories)


def random_motions(n: int, steps: int, dt: float, seed: int = 0) -> cp.GroundMotions:
    """``n`` records of white noise, 1 m/s^2 RMS, ``steps`` samples every ``dt`` s."""
    return cp.GroundMotions(np.random.default_rng(seed).standard_normal((n, steps)), dt)


def untrained_model(
    structure: LinearShearBuilding, operator: dict, steps: int, dt: float
) -> cp.CompositeModel:
    """ELS -> random-weight FNO -> linear regression, with normalisers from a few records."""
    dof = structure.n_outputs
    torch.manual_seed(0)
    model = cp.compose(
        structure=structure,
        preprocessor="els",
        operator=FNO1d(dof + 1, dof, **operator),
        refiner="linear-regression",
    )
    sample = random_motions(4, steps, dt, seed=1)
    z = model.physics(sample)
    time_column = np.broadcast_to(sample.time[None, :, None], (*z.shape[:2], 1))
    model.input_normalizer_ = Normalizer.fit(np.concatenate([z, time_column], axis=2))
    model.output_normalizer_ = Normalizer.fit(z)
    model.validation_rmse_ = z.std(axis=(0, 1))
    model.history_ = TrainingHistory()
    rng = np.random.default_rng(2)
    u = z + 0.1 * z.std() * rng.standard_normal(z.shape)
    model.refiner.fit(z, z + 0.05 * z.std() * rng.standard_normal(z.shape), u, rng)
    return model


def operator_flops(records: int, steps: int, dof: int, operator: dict) -> float:
    """Matrix-product FLOPs of the FNO forward pass (DFTs as the matrix products they are)."""
    width, hidden = operator["width"], operator["projection_width"]
    m = min(operator["modes"], steps // 2 + 1)
    rows = records * steps
    layer = 2 * 2.0 * (2 * m) * steps * records * width + 2.0 * rows * width * width
    ends = 2.0 * rows * (dof + 1) * width + 2.0 * rows * width * hidden + 2.0 * rows * hidden * dof
    return operator["layers"] * layer + ends


def _rss_mib(field: str) -> float:
    """``VmRSS`` (now) or ``VmHWM`` (peak) of this process in MiB, from ``/proc/self/status``."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 1024.0
    raise OSError(f"no {field} in /proc/self/status")


def _prediction_memory(records: int) -> tuple[float, float]:
    """In a fresh process: resident memory (MiB) just before predicting ``records`` Example 1
    records (3001 samples) with ELS -> FNO -> linear regression, and its peak during the
    prediction (the peak is reset through ``/proc/self/clear_refs`` first)."""
    model = untrained_model(LinearShearBuilding(), EXAMPLE1_OPERATOR, 3001, 0.01)
    motions = random_motions(records, 3001, 0.01)
    with open("/proc/self/clear_refs", "w") as clear:
        clear.write("5")
    before = _rss_mib("VmRSS")
    model.predict(motions)
    return before, _rss_mib("VmHWM")


def memory_row(record_counts: tuple[int, ...]) -> Row:
    """Peak resident memory of predicting each of ``record_counts`` Example 1 records, each in
    a fresh process, beside the size of the four arrays the prediction returns."""
    context = multiprocessing.get_context("spawn")
    notes = []
    start = time.perf_counter()
    for records in record_counts:
        with context.Pool(1) as pool:
            before, peak = pool.apply(_prediction_memory, (records,))
        outputs = 4 * records * 3001 * 5 * 8 / 2**20
        notes.append(
            f"{records} records: peak RSS {peak:.0f} MiB, {before:.0f} MiB before predicting, "
            f"returned z, operator output, mean, std {outputs:.0f} MiB, "
            f"so {peak - before - outputs:.0f} MiB of working memory"
        )
    return Row(
        stage=f"predict {' / '.join(map(str, record_counts))} Example 1 records (3001 samples)",
        ours_s=time.perf_counter() - start,
        target="bounded memory",
        notes=[*notes, "time: all runs, each with process start and model set-up"],
    )


def run(quick: bool = False, device: str = "cpu") -> list[Row]:
    records, steps, dt = (16, 1001, 0.005) if quick else (300, 4001, 0.005)
    structure = example3_structure()
    model = untrained_model(structure, EXAMPLE3_OPERATOR, steps, dt).to(device)
    motions = random_motions(records, steps, dt)
    els = best_time(lambda: model.physics(motions))
    stages = model.predict_stages(motions)
    refiner = best_time(lambda: model.refiner.predict(stages.z, stages.operator_output))
    flops = operator_flops(records, steps, structure.n_outputs, EXAMPLE3_OPERATOR)
    width, m = EXAMPLE3_OPERATOR["width"], min(EXAMPLE3_OPERATOR["modes"], steps // 2 + 1)
    chunk = composite.PREDICT_CHUNK
    shapes = [
        (2 * m, steps, chunk * width),
        (steps, 2 * m, chunk * width),
        (chunk * steps, width, width),
        (1024, 1024, 1024),
    ]
    stage = (
        f"predict {records} x {steps} records, ELS -> FNO (8 x 40 modes, width 128, "
        "projection 128) -> linear regression"
    )
    times = {}
    rows = []
    for precision, dtype in (("float32", torch.float32), ("bfloat16", torch.bfloat16)):
        model.predict(motions[:2], precision=precision)
        predict = partial(model.predict, motions, precision=precision)
        total = times[precision] = best_time(predict)
        operator = total - els - refiner
        rate = best_matmul_rate(shapes, repeat=10, device=device, dtype=dtype)
        notes = [
            f"{describe_device(model.device)}; best of 3 after warm-up",
            f"ELS {els:.2f} s, operator and assembly {operator:.2f} s (by difference), "
            f"refiner {refiner:.2f} s",
            f"operator {flops / 1e9:.0f} GFLOP of matrix products, "
            f"{flops / operator / 1e9:.0f} GFLOP/s; FLOP floor at the best {precision} "
            f"matrix-product rate ({rate / 1e9:.0f} GFLOP/s) {flops / rate:.1f} s",
        ]
        row = Row(stage=stage, ours_s=total, target="<= 5 s on 2 CPU cores", notes=notes)
        if precision == "float32":
            row.target += " (paper: under 5 s on a GPU)"
        else:
            low = model.predict_stages(motions, precision=precision).operator_output
            change = np.linalg.norm(low - stages.operator_output)
            row.stage = "the same in bfloat16 (`precision='bfloat16'`)"
            row.alternative, row.alternative_s = "float32", times["float32"]
            row.notes.append(
                f"operator output against float32's (random weights): relative L2 "
                f"{change / np.linalg.norm(stages.operator_output):.1e}; for a trained "
                "model see the bfloat16 row"
            )
        rows.append(row)
    if model.device.type == "cpu":
        rows.append(memory_row((100, 200) if quick else (1000, 2000)))
    return rows
