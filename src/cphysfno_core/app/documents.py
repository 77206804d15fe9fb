"""The JSON documents a run and a study write, typed: a key that is not in the schema
fails when the document is written, and a file read is checked against it.

Each document carries ``schema_version``; a file written before the field existed reads
as version 1.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, ClassVar, Self

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from ..signals.errors import ConfigError


class Row(BaseModel):
    """A part of a document: its keys are the schema's, no others."""

    model_config = ConfigDict(extra="forbid")


class Document(Row):
    """A document with a schema version, read from and written to a JSON file.

    Keys absent from a document stay absent when it is written again; NaN is written as
    ``NaN``, as :func:`json.dumps` does.
    """

    SCHEMA_VERSION: ClassVar[int] = 1
    """The version this code writes and the newest it reads."""

    schema_version: int = Field(1, ge=1)

    @field_validator("schema_version")
    @classmethod
    def _readable(cls, version: int) -> int:
        if version > cls.SCHEMA_VERSION:
            raise ValueError(
                f"schema version {version} is newer than this cphysfno reads "
                f"({cls.SCHEMA_VERSION}): update cphysfno"
            )
        return version

    @classmethod
    def read(cls, path: str | Path) -> Self:
        """The document in the JSON file ``path``.

        Raises:
            ConfigError: the file does not hold such a document (the message says where).
        """
        try:
            return cls.model_validate(json.loads(Path(path).read_text()))
        except (ValidationError, json.JSONDecodeError) as error:
            message = f"{path} is not a {cls.__name__} this cphysfno reads: {error}"
            raise ConfigError(message) from error

    def to_json(self) -> dict[str, Any]:
        """The document as JSON data, ``schema_version`` first and set to the current
        version."""
        data = self.model_dump(exclude_unset=True, exclude={"schema_version"})
        return {"schema_version": self.SCHEMA_VERSION, **data}

    def write(self, path: str | Path) -> Path:
        """Write the document to ``path`` (indented JSON); return the path."""
        path = Path(path)
        path.write_text(json.dumps(self.to_json(), indent=2))
        return path
