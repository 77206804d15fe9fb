"""The records of a generation counted by the hardest measure their analysis needed to
converge (:attr:`~cphysfno_core.Responses.recoveries`: an OpenSees structure's convergence
ladder)."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping

import numpy as np


def convergence_summary(recoveries: Mapping[int, str], complete: np.ndarray) -> str:
    """``"convergence: 180 complete records needed no retry; 12 needed substeps dt/4, 3
    needed a looser test"``: how many of the ``complete [n]`` (bool) records needed
    nothing, then each measure of ``recoveries`` (record index -> the hardest one that
    record needed, in words) with the records that needed it, most frequent first. Empty
    when no record needed one."""
    if not recoveries:
        return ""
    plain = np.asarray(complete, dtype=bool).copy()
    plain[list(recoveries)] = False
    needed = Counter(recoveries.values()).most_common()
    counts = ", ".join(f"{count} needed {measure}" for measure, count in needed)
    return f"convergence: {int(plain.sum())} complete records needed no retry; {counts}"
