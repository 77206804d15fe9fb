"""Tasks for worker-process tests (importable in spawned workers)."""

import time
from pathlib import Path


def fail_or_finish_late(key: int, folder: str) -> int:
    """Task 0 fails after a second; any other task sleeps 8 s, then leaves a marker file."""
    if key == 0:
        time.sleep(1.0)
        raise RuntimeError("task 0 failed")
    time.sleep(8.0)
    (Path(folder) / f"finished-{key}").write_text("done")
    return key
