"""``metrics.json`` and ``study.json`` are typed: what the code writes is checked against
the schema, and files of earlier versions read as they were written."""

import json
from pathlib import Path

import pytest
from pydantic import ValidationError

import cphysfno_core as cp
from cphysfno_core.app.metrics_document import MetricsDocument
from cphysfno_core.app.study_document import StudySummary

RESULTS = Path(__file__).parents[1] / "results"

ROW = {"rmse": [0.01], "rel_l2": [0.2]}


def _metrics(**rows):
    return {"models": rows, "output_names": ["roof"], "sizes": {"test": 3}, "epochs": 1}


@pytest.mark.parametrize(
    "document, path",
    [
        (MetricsDocument, "rc-frame.json"),  # a run's metrics.json
        (StudySummary, "example1-data-efficiency.json"),  # before baselines and response_rms
        (StudySummary, "example1-learning-curve.json"),
    ],
)
def test_files_written_before_the_schema_version_read_as_version_1(document, path, tmp_path):
    """A recorded document with its ``schema_version`` taken out (as files written before
    there was one have none) reads as version 1 and writes back the same."""
    original = json.loads((RESULTS / path).read_text())
    original.pop("schema_version", None)
    legacy = tmp_path / "legacy.json"
    legacy.write_text(json.dumps(original))
    read = document.read(legacy)
    assert read.schema_version == 1
    written = json.loads(read.write(tmp_path / "again.json").read_text())
    assert written.pop("schema_version") == 1
    assert json.dumps(written, sort_keys=True) == json.dumps(original, sort_keys=True)


def test_a_key_that_is_not_in_the_schema_fails_when_written():
    with pytest.raises(ValidationError, match="coverage68"):
        MetricsDocument.model_validate(_metrics(fno={**ROW, "coverage68": [0.7]}))
    with pytest.raises(ValidationError, match="baseline_beat_surrogates"):
        MetricsDocument.model_validate({**_metrics(fno=ROW), "baseline_beat_surrogates": []})


def test_errors_of_any_edp_are_kept():
    errors = {name: {"median": [0.1], "p90": [0.3]} for name in ("PID", "PFV", "PD")}
    document = MetricsDocument.model_validate(_metrics(fno={**ROW, "edp": errors}))
    assert document.to_json()["models"]["fno"]["edp"] == errors


def test_a_file_of_a_newer_version_or_another_kind_is_refused(tmp_path):
    newer = tmp_path / "metrics.json"
    newer.write_text(json.dumps({**_metrics(fno=ROW), "schema_version": 2}))
    with pytest.raises(
        cp.ConfigError, match="(?s)metrics.json is not a MetricsDocument.*version 2 is newer"
    ):
        MetricsDocument.read(newer)
    with pytest.raises(cp.ConfigError, match="is not a StudySummary"):
        StudySummary.read(newer)
