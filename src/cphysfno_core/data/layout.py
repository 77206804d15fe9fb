"""The layout of a run's output folder."""

from pathlib import Path

DATASET = "dataset.h5"
"""The simulated records, with every physics response (see :mod:`.datasets`)."""

MODELS = "models"
"""The folder of trained models, one ``models/<label>/`` each."""

CONFIG = "config.json"
"""The run's experiment config, as plain data."""

STUDY_SUMMARY = "study.json"
"""What marks a study's folder: its summary over the runs, which live under ``runs/``."""


def run_file(run: Path, name: str) -> Path:
    """``run/name``; for a run of a study (a folder under ``STUDY/runs/``), which holds
    neither the dataset nor the config, the study's own ``STUDY/name`` where ``run`` has
    none (the study's runs share its dataset, and their configs differ only in training)."""
    own = run / name
    if own.is_file():
        return own
    study = next((f for f in run.resolve().parents if (f / STUDY_SUMMARY).is_file()), None)
    if study is not None and (study / name).is_file():
        return study / name
    return own
