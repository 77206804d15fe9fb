"""``cphysfno inspect FILE``: what a dataset or a prediction file holds, in words."""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np

from ..data.datasets import read_draws, read_provenance
from ..data.recoveries import convergence_summary
from ..signals.errors import DatasetError


def describe_file(path: str | Path, records: int = 5) -> str:
    """Every array of ``path`` (a ``dataset.h5`` or a prediction ``.npz``) with its shape,
    dtype, units and description; for a dataset also its attributes and the provenance of
    its first ``records`` records.

    Raises:
        DatasetError: the file is missing or neither kind.
    """
    path = Path(path)
    if not path.is_file():
        raise DatasetError(f"{path}: no such file")
    if path.suffix == ".npz":
        return _describe_predictions(path)
    try:
        with h5py.File(path, "r") as f:
            return _describe_dataset(path, f, records)
    except OSError as error:
        raise DatasetError(f"{path} is neither an HDF5 dataset nor an .npz file: {error}") from None


def _describe_dataset(path: Path, f: h5py.File, records: int) -> str:
    lines = [f"{path}: cphysfno dataset", ""]
    for key in ("dt", "seed", "n_train", "n_val", "n_test", "complete"):
        if key in f.attrs:
            lines.append(f"  {key}: {f.attrs[key]}")
    failures = json.loads(f.attrs.get("failures", "{}"))
    collapsed = int(f["collapsed"][...].sum()) if "collapsed" in f else 0
    stopped = json.loads(f.attrs.get("non_converged", "{}"))
    recoveries = {int(i): m for i, m in json.loads(f.attrs.get("recoveries", "{}")).items()}
    complete = ~f["collapsed"][...] if "collapsed" in f else np.ones(f["u"].shape[0], bool)
    complete[[int(i) for i in (*failures, *stopped)]] = False
    lines += [
        f"  failed records: {len(failures)}",
        f"  collapsed records: {collapsed}",
        f"  non-converged records (below the collapse): {len(stopped)}",
        *(f"    record {index}: {cause}" for index, cause in list(stopped.items())[:5]),
        *([f"  {summary}"] if (summary := convergence_summary(recoveries, complete)) else []),
        "",
    ]
    arrays: list[tuple[str, h5py.Dataset]] = []
    f.visititems(
        lambda name, item: arrays.append((name, item)) if isinstance(item, h5py.Dataset) else None
    )
    for name, item in arrays:
        units = item.attrs.get("units", "(not recorded)")
        description = item.attrs.get("description", "")
        lines.append(
            f"  {name:<22} {str(item.shape):<20} {item.dtype!s:<8} [{units}] {description}"
        )
    lines += _describe_draws(f)
    provenance = read_provenance(f)
    lines += ["", f"provenance of {min(records, len(provenance))} of {len(provenance)} records:"]
    lines += [f"  {i}: {json.dumps(p)}" for i, p in enumerate(provenance[:records])]
    return "\n".join(lines)


def _describe_draws(f: h5py.File) -> list[str]:
    """The random structural parameters of the open dataset ``f``, each with its unit and
    the minimum, median and maximum of its draws; nothing for a fixed structure."""
    drawn = read_draws(f)
    if not drawn:
        return []
    values = drawn["params"]
    lines = ["", f"random structural parameters ({values.shape[0]} draws, one a record):"]
    for j, (name, unit) in enumerate(zip(drawn["param_names"], drawn["param_units"], strict=True)):
        low, median, high = np.nanquantile(values[:, j], (0.0, 0.5, 1.0))
        lines.append(
            f"  {name:<30} [{unit or 'no unit'}] min {low:.6g}, median {median:.6g}, max {high:.6g}"
        )
    return lines


def _describe_predictions(path: Path) -> str:
    with np.load(path, allow_pickle=False) as stored:
        descriptions = json.loads(str(stored["descriptions"])) if "descriptions" in stored else {}
        lines = [
            f"{path}: predictions of model '{descriptions.get('model', '(not recorded)')}'",
            "",
        ]
        for name in stored.files:
            if name == "descriptions":
                continue
            value = stored[name]
            units, description = descriptions.get(name, ["(not recorded)", ""])
            lines.append(
                f"  {name:<16} {str(value.shape):<20} {value.dtype!s:<8} [{units}] {description}"
            )
    return "\n".join(lines)
