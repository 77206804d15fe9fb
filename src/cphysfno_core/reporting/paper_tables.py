"""The paper's result tables, printed beside ours in reports (``[output] paper_reference``).

Each table maps a model label (as in ``metrics.json``) to ``(RMSE [m], relative L2)`` per
output DOF, both means over the paper's 10 training runs. The paper's "C-PhysFNO" of
Examples 2 and 3 is its ELS variant: the elastic bridge, and the frame's pushover shear model.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class PaperTable:
    """One of the paper's result tables.

    Attributes:
        caption: where it comes from and how it was made, for a report line.
        rows: label -> ``([n_outputs] RMSE in m, [n_outputs] relative L2)``.
    """

    caption: str
    rows: dict[str, tuple[list[float], list[float]]]

    def beside(self, label: str, metric: str, cells: list[str], digits: int) -> list[str]:
        """``cells`` (ours, one per DOF) each followed by the paper's value in parentheses,
        when the paper has the row ``label`` for ``metric`` (``"rmse"`` or ``"rel_l2"``)
        with as many DOFs; else ``cells`` unchanged."""
        published = self.rows.get(label)
        if published is None:
            return cells
        values = published[0 if metric == "rmse" else 1]
        if len(values) != len(cells):
            return cells
        return [f"{c} ({p:.{digits}f})" for c, p in zip(cells, values, strict=True)]


EXAMPLE1 = PaperTable(
    "Table 1 (five-story Bouc-Wen building; 10 seeds, 100 epochs, 400/100/200 records)",
    {
        "fno": (
            [0.0038, 0.0072, 0.0105, 0.0140, 0.0187],
            [0.9653, 0.9569, 0.9561, 0.9578, 0.9582],
        ),
        "c-physfno-els": (
            [0.0022, 0.0040, 0.0054, 0.0070, 0.0102],
            [0.5775, 0.5314, 0.4957, 0.4819, 0.5245],
        ),
        "c-physfno-modal": (
            [0.0028, 0.0053, 0.0077, 0.0103, 0.0139],
            [0.7196, 0.7059, 0.7025, 0.7034, 0.7134],
        ),
        "c-physfno-relaxed": (
            [0.0025, 0.0048, 0.0070, 0.0094, 0.0126],
            [0.6398, 0.6393, 0.6404, 0.6421, 0.6485],
        ),
        "refined-c-physfno-els": (
            [0.0021, 0.0039, 0.0053, 0.0069, 0.0100],
            [0.5492, 0.5200, 0.4882, 0.4780, 0.5208],
        ),
        "refined-c-physfno-modal": (
            [0.0027, 0.0052, 0.0076, 0.0102, 0.0138],
            [0.7015, 0.6820, 0.6832, 0.6850, 0.7002],
        ),
        "refined-c-physfno-relaxed": (
            [0.0024, 0.0047, 0.0069, 0.0093, 0.0125],
            [0.6180, 0.6282, 0.6302, 0.6310, 0.6402],
        ),
    },
)

EXAMPLE2 = PaperTable(
    "Table 3 (Auburn Ravine bridge, pier tops; 10 seeds, 600/100/300 records)",
    {
        "fno": (
            [0.0061, 0.0060, 0.0059, 0.0059, 0.0057, 0.0059, 0.0060, 0.0061, 0.0062, 0.0062],
            [0.6402, 0.6415, 0.6370, 0.6385, 0.6343, 0.6436, 0.6405, 0.6439, 0.6398, 0.6416],
        ),
        "c-physfno-els": (
            [0.0046, 0.0047, 0.0045, 0.0045, 0.0044, 0.0046, 0.0046, 0.0046, 0.0047, 0.0047],
            [0.4873, 0.4939, 0.4845, 0.4919, 0.4855, 0.4994, 0.4930, 0.4895, 0.4882, 0.4903],
        ),
        "refined-c-physfno-els": (
            [0.0046, 0.0047, 0.0046, 0.0046, 0.0045, 0.0047, 0.0047, 0.0047, 0.0047, 0.0048],
            [0.4902, 0.4980, 0.4880, 0.4939, 0.4900, 0.5045, 0.4992, 0.4945, 0.4912, 0.4955],
        ),
    },
)

EXAMPLE3 = PaperTable(
    "Table 5 (SAC nine-story frame, floors; 10 seeds, 600/100/300 records)",
    {
        "fno": (
            [0.0011, 0.0017, 0.0024, 0.0031, 0.0035, 0.0040, 0.0045, 0.0051, 0.0056],
            [0.2629, 0.2481, 0.2458, 0.2481, 0.2381, 0.2345, 0.2318, 0.2296, 0.2323],
        ),
        "c-physfno-els": (
            [0.0009, 0.0015, 0.0020, 0.0024, 0.0028, 0.0032, 0.0036, 0.0041, 0.0046],
            [0.2055, 0.1978, 0.1889, 0.1795, 0.1753, 0.1718, 0.1679, 0.1693, 0.1749],
        ),
        "refined-c-physfno-els": (
            [0.0009, 0.0015, 0.0020, 0.0024, 0.0028, 0.0032, 0.0035, 0.0041, 0.0045],
            [0.2054, 0.1976, 0.1887, 0.1794, 0.1752, 0.1716, 0.1678, 0.1692, 0.1748],
        ),
    },
)

PAPER_TABLES = {"example1": EXAMPLE1, "example2": EXAMPLE2, "example3": EXAMPLE3}
"""``[output] paper_reference`` -> the table printed beside ours."""


def paper_table(reference: str) -> PaperTable | None:
    """The paper's table for ``reference`` (``"example1"`` ...), None for ``"none"``."""
    return PAPER_TABLES.get(reference)
