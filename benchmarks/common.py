"""Timing helpers and the result table shared by the benchmark modules."""

from __future__ import annotations

import os
import platform
import resource
import time
from collections.abc import Callable
from dataclasses import dataclass, field


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
    """

    stage: str
    ours_s: float
    alternative: str = ""
    alternative_s: float | None = None
    target: str = ""
    notes: list[str] = field(default_factory=list)

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
        "| stage | ours (s) | alternative | alternative (s) | ratio | target | notes |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        alt = "-" if r.alternative_s is None else f"{r.alternative_s:.4g}"
        ratio = "-" if r.ratio is None else f"{r.ratio:,.1f}x"
        lines.append(
            f"| {r.stage} | {r.ours_s:.4g} | {r.alternative or '-'} | {alt} | {ratio} | "
            f"{r.target} | {'; '.join(r.notes)} |"
        )
    return "\n".join(lines)
