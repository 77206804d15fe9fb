"""Timing helpers and the result table shared by the benchmark modules."""

from __future__ import annotations

import os
import platform
import resource
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Timing:
    """How a wall time was taken: what a speed ratio must state for both sides.

    Attributes:
        threads: cores the work could use (the process's CPU affinity).
        warm: whether untimed calls ran first (compilation, caches, page faults paid).
        runs: timed calls.
        statistic: ``"median"`` of the runs, or ``"single"`` for one run.
    """

    threads: int
    warm: bool
    runs: int
    statistic: str = "median"

    def __str__(self) -> str:
        state = "warm" if self.warm else "cold"
        return f"{self.threads} thr, {state}, {self.statistic} of {self.runs}"


@dataclass
class Row:
    """One line of the results table.

    Attributes:
        stage: what is measured (e.g. "Bouc-Wen data, 1000 x 3001").
        ours_s: our wall time in s.
        alternative: what it is compared with ("" if nothing).
        alternative_s: the alternative's wall time in s (None if not measured).
        target: the target, in words.
        notes: accuracy figures and how the alternative was measured.
        ours_timing: how ``ours_s`` was taken (None: not stated, shown as such).
        alternative_timing: how ``alternative_s`` was taken.
    """

    stage: str
    ours_s: float
    alternative: str = ""
    alternative_s: float | None = None
    target: str = ""
    notes: list[str] = field(default_factory=list)
    ours_timing: Timing | None = None
    alternative_timing: Timing | None = None

    @property
    def ratio(self) -> float | None:
        if self.alternative_s is None:
            return None
        return self.alternative_s / self.ours_s


def best_time(function: Callable[[], object], repeat: int = 3, warmup: int = 1) -> float:
    """Fastest wall time in s of ``repeat`` calls after ``warmup`` untimed calls."""
    for _ in range(warmup):
        function()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def median_time(
    function: Callable[[], object], runs: int = 5, warmup: int = 1
) -> tuple[float, Timing]:
    """Median wall time in s of ``runs`` calls after ``warmup`` untimed calls, with how it
    was taken (threads: the cores this process may run on)."""
    for _ in range(warmup):
        function()
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return float(np.median(times)), Timing(cores(), warmup > 0, runs)


def cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


@contextmanager
def on_cores(n: int) -> Iterator[None]:
    """Run the block on the first ``n`` cores only (CPU affinity, which the compiled
    kernels' thread pools and torch follow), then restore the affinity."""
    before = os.sched_getaffinity(0)
    os.sched_setaffinity(0, sorted(before)[:n])
    threads = None
    try:
        import torch

        threads = torch.get_num_threads()
        torch.set_num_threads(n)
    except ImportError:
        pass
    try:
        yield
    finally:
        os.sched_setaffinity(0, before)
        if threads is not None:
            import torch

            torch.set_num_threads(threads)


def peak_rss_mib() -> float:
    """Peak resident set size of this process so far, MiB."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def load_average() -> str:
    """The 1-, 5- and 15-minute load averages, as /proc/loadavg gives them."""
    try:
        with open("/proc/loadavg") as f:
            return " ".join(f.read().split()[:3])
    except OSError:
        return "unknown"


def machine() -> str:
    """A one-line description of this machine."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}"


def format_rows(rows: list[Row]) -> str:
    """A Markdown table of the rows."""
    lines = [
        "| stage | ours (s) | ours: threads, warm, runs | alternative | alternative (s) | "
        "alternative: threads, warm, runs | ratio | target | notes |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        alt = "-" if r.alternative_s is None else f"{r.alternative_s:.4g}"
        ratio = "-" if r.ratio is None else f"{r.ratio:,.1f}x"
        ours_how = "not stated" if r.ours_timing is None else str(r.ours_timing)
        alt_how = "-" if r.alternative_s is None else str(r.alternative_timing or "not stated")
        lines.append(
            f"| {r.stage} | {r.ours_s:.4g} | {ours_how} | {r.alternative or '-'} | {alt} | "
            f"{alt_how} | {ratio} | {r.target} | {'; '.join(r.notes)} |"
        )
    return "\n".join(lines)
