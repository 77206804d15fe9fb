"""Experiment configuration: one TOML file, validated with pydantic before any work starts.

Each component section is ``name = "..."`` plus that component's own fields, which are
checked against the component's ``Params`` model once plugins are discovered, so a wrong
field fails with its path (``operator.modes: ...``). A component field typed as a path
(``pathlib.Path``) that is relative in a config file is taken from that file's folder.
"""

from __future__ import annotations

import tomllib
import types
import typing
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from ..api.interfaces import format_validation_error, validate_params
from ..api.kinds import KINDS
from ..api.registry import Registry, get_registry
from ..signals.errors import ConfigError
from .precision import Precision
from .toml_writer import dumps
from .uncertainty import UncertainParameters, random_parameters, with_values


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class ComponentSpec(BaseModel):
    """A component by registry name with its parameters (all other keys of the section)."""

    model_config = ConfigDict(extra="allow")

    name: str = Field(min_length=1)

    @property
    def params(self) -> dict[str, Any]:
        return dict(self.model_extra or {})

    @classmethod
    def of(cls, name: str, params: dict[str, Any] | None = None) -> ComponentSpec:
        return cls(name=name, **(params or {}))

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, **self.params}


class StructureSpec(ComponentSpec):
    """The structure by registry name with its parameters, any number among which may be a
    distribution (:mod:`.uncertainty`): each record of a dataset then gets its own draw."""

    @property
    def params(self) -> dict[str, Any]:
        """The nominal structure's parameters: each random one at its distribution's
        median. :meth:`to_dict` keeps the distributions."""
        raw = dict(self.model_extra or {})
        nominal = {p.path: p.distribution.nominal for p in random_parameters(raw)}
        return with_values(raw, nominal)

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, **(self.model_extra or {})}


class UncertaintyConfig(_Strict):
    """How the structure's random parameters vary together."""

    correlations: list[tuple[str, str, Annotated[float, Field(gt=-1.0, lt=1.0)]]] = Field(
        default_factory=list,
        description="[path, path, rho]: the correlation of two random parameters of the "
        "structure (by dotted path, e.g. 'stiffnesses.0'), a Gaussian copula; the others "
        "are independent",
    )
    test_tails: float | None = Field(
        None,
        gt=0.0,
        description="c: the training and validation records draw every random parameter "
        "from its central range (its standard normal number within [-c, c]) and the test "
        "records from its tails (beyond c on either side): a test of the models on "
        "structures outside the family they were trained on (default: every record draws "
        "from the whole distributions)",
    )
    physics: Literal["fit", "surface"] = Field(
        "fit",
        description="how each record's physics preprocessor is made: 'fit' fits it to the "
        "record's own structure; 'surface' fits it to 2 k + 1 members of the family (the "
        "nominal one and one on either side along each of the k parameters) and "
        "interpolates its calibration between them (preprocessors with a calibration, "
        "such as the stick; the others are fitted to each record)",
    )


class DataConfig(_Strict):
    """How many records to simulate, how to split them, and how to run the simulations."""

    n_train: int = Field(400, gt=0)
    n_val: int = Field(100, gt=0)
    n_test: int = Field(200, gt=0)
    seed: int = 0
    group_by: str | None = Field(
        None,
        min_length=1,
        description="metadata key of the ground motions whose records stay in one split "
        "(e.g. 'rsn': both components of a recording and all their scaled copies); whole "
        "groups are dealt to train, val and test, which must then be sums of group sizes",
    )
    chunk_size: int = Field(100, gt=0, description="records per simulation task")
    executor: Literal["serial", "processes", "dask"] = "processes"
    workers: int | None = Field(
        None,
        gt=0,
        description="local processes or LocalCluster workers; default: the CPUs this "
        "process may run on",
    )
    address: str | None = Field(
        None, description="address of a running dask.distributed scheduler (executor 'dask')"
    )
    retries: int = Field(2, ge=0, description="reruns of a failed Dask task")
    on_failure: Literal["raise", "skip"] = Field(
        "raise",
        description="a record whose simulation fails stops the run, or is skipped "
        "and listed in the dataset",
    )

    @model_validator(mode="after")
    def _address_needs_dask(self) -> DataConfig:
        if self.address is not None and self.executor != "dask":
            raise ValueError("address is for executor = 'dask'")
        return self

    @property
    def n_records(self) -> int:
        return self.n_train + self.n_val + self.n_test


class TrainingConfig(_Strict):
    """Optimiser and schedule (paper: Adam 1e-3, batch 20, halve the rate every 10 epochs)."""

    epochs: int = Field(100, gt=0)
    batch_size: int = Field(20, gt=0)
    learning_rate: float = Field(1e-3, gt=0)
    decay_step: int = Field(10, gt=0, description="epochs between learning-rate decays")
    decay_factor: float = Field(0.5, gt=0, le=1)
    weight_decay: float = Field(
        0.0,
        ge=0,
        description="decoupled weight decay (AdamW): every step multiplies each weight by "
        "1 - learning_rate * weight_decay. Not an L2 term in the loss: under Adam that term "
        "shrinks every weight whose loss gradient is zero (all hidden layers at the start of "
        "a residual model, whose output layer starts at zero) by about the learning rate a "
        "step, and kills the network",
    )
    loss: Literal["relative-l2"] = "relative-l2"
    normalize: bool = Field(
        True,
        description="standardise each input and target channel (mean and std over the "
        "training split); false feeds the operator raw SI values (time in s, displacements "
        "in m), as the authors' published MATLAB code does",
    )
    seed: int = 0
    threads: int | None = Field(None, gt=0, description="torch CPU threads; default: all")
    device: str = Field(
        "auto",
        pattern=r"^(auto|cpu|cuda(:\d+)?|mps)$",
        description="where the operator trains and predicts: 'auto' (the GPU when torch "
        "sees one, else the CPU), 'cpu', 'cuda', 'cuda:N' or 'mps'",
    )
    train_records: int | None = Field(
        None,
        gt=0,
        description="train on the first n records of the training split (default: all of "
        "it), for data-efficiency studies on one dataset",
    )
    precision: Precision = Field(
        "float32",
        description="arithmetic of the operator's forward and backward passes: 'bfloat16' "
        "runs them under torch.autocast (about 1.7x faster per epoch on a CPU with native "
        "bfloat16, e.g. avx512_bf16 or AMX, and on recent GPUs); weights, gradients, "
        "optimiser and loss stay float32",
    )


class FormulationConfig(_Strict):
    """How a C-Phys model's operator works on the physics response z (the baseline, which
    has no z, keeps only the response kinds it learns and its parameter inputs), and which
    responses it learns. The paper's formulation is the default: ``[z, t] -> u``."""

    residual: bool | Literal["choose"] = Field(
        False,
        description="true: the operator learns the correction u - z, its output layer "
        "starting at zero so that training starts from the physics response, and the "
        "prediction is z plus its output; 'choose' (for a run): train both forms, report "
        "both, and name the one with the lower validation error",
    )
    ground_motion_input: bool = Field(
        False, description="feed a_g as an input channel beside z and t"
    )
    accelerations: bool = Field(
        False,
        description="the operator (of every model, the baseline's too) also learns the "
        "absolute accelerations of the outputs (the structure's 'absolute_acceleration' "
        "channel), normalised and weighted in the loss on their own; floor accelerations "
        "(PFA) then come from the predicted accelerations, not from the displacements",
    )
    responses: bool = Field(
        False,
        description="the operator (of every model, the baseline's too) also learns the "
        "structure's named responses ([structure] responses: a base shear, an isolator's "
        "force), each normalised and weighted in the loss on its own; their peaks (EDP PR) "
        "and their pelicun demands then come from the surrogate",
    )

    parameter_input: bool | Literal["both"] = Field(
        False,
        description="for a structure with random parameters: true: the operator (of every "
        "model, the baseline's too) also takes each record's parameters as constant input "
        "channels, standardised by the training draws; 'both' (for a run): train every "
        "model with and without them (the label of a model with them ends in '-params')",
    )

    def physics_free(self) -> FormulationConfig:
        """The part of this formulation a model without physics response keeps: the
        response kinds it learns and its parameter inputs."""
        return FormulationConfig(
            accelerations=self.accelerations,
            responses=self.responses,
            parameter_input=self.parameter_input,
        )

    def forms(self) -> list[FormulationConfig]:
        """The concrete formulations this one trains: itself, with ``residual =
        'choose'`` the paper's form and the residual form, and with ``parameter_input =
        'both'`` each without and with the parameter inputs."""
        residuals = (False, True) if self.residual == "choose" else (self.residual,)
        inputs = (False, True) if self.parameter_input == "both" else (self.parameter_input,)
        return [
            self.model_copy(update={"residual": residual, "parameter_input": parameter_input})
            for parameter_input in inputs
            for residual in residuals
        ]


class OutputConfig(_Strict):
    """What the run trains and writes."""

    baseline: bool = Field(True, description="also train the plain operator on [a_g, t]")
    models: list[str] | None = Field(
        None,
        min_length=1,
        description="train and evaluate only these of the config's models, by label "
        "('fno', 'c-physfno-els'; a refined model comes with its own): a share of a study "
        "(default: every model)",
    )
    figures: bool = True
    paper_reference: Literal["example1", "example2", "example3", "none"] = Field(
        "none", description="print this paper example's table beside ours (Tables 1, 3, 5)"
    )


class SweepConfig(_Strict):
    """One parametric sweep of a study: a config field set to each value in turn."""

    field: str = Field(
        pattern=r"^[a-z_]+\.[a-z_]+$",
        description="dotted path of the field, e.g. 'training.train_records' or 'operator.layers'",
    )
    values: list[int | float | str] = Field(min_length=1)
    label: str | None = Field(None, description="axis label of the sweep's figure")


class StudyConfig(_Strict):
    """Repeated training runs over seeds, and parametric sweeps (``cphysfno study``)."""

    seeds: list[int] = Field(default_factory=lambda: list(range(10)), min_length=1)
    sweeps: dict[str, SweepConfig] = Field(
        default_factory=dict, description="name -> sweep; each runs every seed"
    )
    sweep_preprocessors: list[str] | None = Field(
        None,
        description="the C-Phys variants trained in the sweeps, beside the baseline "
        "(default: every preprocessor)",
    )


class ExperimentConfig(_Strict):
    """A whole study: structure, excitation, physics preprocessors, operator, refiner."""

    structure: StructureSpec
    ground_motion: ComponentSpec
    preprocessor: list[ComponentSpec] = Field(default_factory=list)
    operator: list[ComponentSpec] = Field(
        min_length=1,
        description="one [operator] table, or several [[operator]] tables: every model is "
        "trained with each operator",
    )
    refiner: ComponentSpec | None = None
    data: DataConfig = Field(default_factory=DataConfig)
    training: TrainingConfig = Field(default_factory=TrainingConfig)
    formulation: FormulationConfig = Field(default_factory=FormulationConfig)
    output: OutputConfig = Field(default_factory=OutputConfig)
    study: StudyConfig | None = None
    uncertainty: UncertaintyConfig | None = None

    @field_validator("preprocessor", "operator", mode="before")
    @classmethod
    def _one_or_many(cls, value: Any) -> Any:
        return [value] if isinstance(value, dict) else value

    @model_validator(mode="after")
    def _distinct_preprocessors(self) -> ExperimentConfig:
        names = [p.name for p in self.preprocessor]
        if len(set(names)) != len(names):
            raise ValueError(f"each preprocessor may appear once, got {names}")
        operators = [o.name for o in self.operator]
        if len(set(operators)) != len(operators):
            raise ValueError(f"each operator may appear once, got {operators}")
        if not names and not self.output.baseline:
            raise ValueError("nothing to train: add a [[preprocessor]] or set output.baseline")
        if self.study is not None and self.study.sweep_preprocessors is not None:
            unknown = sorted(set(self.study.sweep_preprocessors) - set(names))
            if unknown:
                raise ValueError(f"study.sweep_preprocessors {unknown} are not among {names}")
        if (self.training.train_records or 0) > self.data.n_train:
            raise ValueError(
                f"training.train_records = {self.training.train_records} exceeds "
                f"data.n_train = {self.data.n_train}"
            )
        return self

    def uncertain_parameters(self) -> UncertainParameters:
        """The structure's random parameters and their correlations (none: a fixed
        structure).

        Raises:
            ConfigError: a distribution or a correlation is invalid (the message names it).
        """
        correlations = self.uncertainty.correlations if self.uncertainty else []
        tails = self.uncertainty.test_tails if self.uncertainty else None
        return UncertainParameters.of(self.structure.to_dict(), correlations, test_tails=tails)

    def to_dict(self) -> dict[str, Any]:
        """The config as plain data (JSON types), its sections in the order of the fields."""
        data = self.model_dump(
            mode="json",
            exclude={kind.name for kind in KINDS},
        )
        data["structure"] = self.structure.to_dict()
        data["ground_motion"] = self.ground_motion.to_dict()
        operators = [o.to_dict() for o in self.operator]
        data["operator"] = operators[0] if len(operators) == 1 else operators
        data["preprocessor"] = [p.to_dict() for p in self.preprocessor]
        if self.refiner is not None:
            data["refiner"] = self.refiner.to_dict()
        return {name: data[name] for name in type(self).model_fields if name in data}

    def to_toml(self) -> str:
        """The config as TOML text; ``parse_config(tomllib.loads(text))`` gives it back."""
        return dumps(self.to_dict())


def check_components(config: ExperimentConfig, registry: Registry | None = None) -> None:
    """Check every component name and its fields against the registry; raise ConfigError."""
    registry = registry or get_registry()
    for kind in (k for k in KINDS if k.name in ExperimentConfig.model_fields):
        value = getattr(config, kind.name)
        specs = value if isinstance(value, list) else [] if value is None else [value]
        for i, spec in enumerate(specs):
            where = kind.name if len(specs) == 1 else f"{kind.name}[{i}]"
            try:
                cls = registry.get(kind.name, spec.name)
            except LookupError as error:
                raise ConfigError(f"{where}.name: {error}") from None
            validate_params(cls.Params, spec.params, where)


def parse_config(data: dict[str, Any], registry: Registry | None = None) -> ExperimentConfig:
    """Validate a config mapping (as read from TOML); every problem names its field."""
    try:
        config = ExperimentConfig.model_validate(data)
    except ValidationError as error:
        raise ConfigError(format_validation_error(error)) from None
    random = config.uncertain_parameters().parameters
    if config.formulation.parameter_input and not random:
        raise ConfigError(
            "formulation.parameter_input: the structure has no random parameter to take as "
            "input (give one a distribution, e.g. { dist = \"lognormal\", median = ..., "
            "beta = ... })"
        )
    check_components(config, registry)
    return config


def load_config(path: str | Path, registry: Registry | None = None) -> ExperimentConfig:
    """Read and validate an experiment TOML file.

    Relative paths in component fields typed as paths (an OpenSees script, a folder of
    records) are taken from the file's folder, so the config runs from any directory.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as error:
        raise ConfigError(f"cannot read config {path}: {error.strerror}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ConfigError(f"{path} is not valid TOML: {error}") from None
    try:
        return parse_config(_paths_from(path.parent, data, registry), registry)
    except ConfigError as error:
        raise ConfigError(f"{path}: {error}") from None


def _paths_from(folder: Path, data: dict[str, Any], registry: Registry | None) -> dict[str, Any]:
    """``data`` with the relative path fields of its components joined to ``folder``."""
    registry = registry or get_registry()
    resolved = dict(data)
    for kind in (k for k in KINDS if k.name in ExperimentConfig.model_fields):
        value = data.get(kind.name)
        sections = value if isinstance(value, list) else [value]
        if not all(isinstance(s, dict) and isinstance(s.get("name"), str) for s in sections):
            continue  # left for validation to report
        joined = []
        for section in sections:
            try:
                params = registry.get(kind.name, section["name"]).Params
            except LookupError:
                joined.append(section)
                continue
            joined.append(
                {
                    key: str(folder / item)
                    if key in params.model_fields
                    and _is_path(params.model_fields[key].annotation)
                    and isinstance(item, str)
                    and not Path(item).expanduser().is_absolute()
                    else item
                    for key, item in section.items()
                }
            )
        resolved[kind.name] = joined if isinstance(value, list) else joined[0]
    return resolved


def _is_path(annotation: Any) -> bool:
    """Whether a field annotation is ``Path`` or ``Path | None``."""
    if annotation is Path:
        return True
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        return any(_is_path(arg) for arg in typing.get_args(annotation))
    return False
