"""Named responses of a user's model: any node or element response OpenSees can give, read
at every step beside the outputs' displacements (a base shear from the support reactions,
an isolator's force or deformation, a column's end moment)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from cphysfno_core.signals import ResponseChannel

from .source import ScriptError

NODE_KINDS = ("nodeReaction", "nodeDisp", "nodeVel", "nodeAccel")
"""Node responses: one DOF of each node named, summed."""


class ResponseParams(BaseModel):
    """One named response of ``opensees-model``: a node response (``nodeReaction``,
    ``nodeDisp``, ``nodeVel``, ``nodeAccel``) at DOF ``dof`` of each of ``nodes``, or the
    component ``component`` of ``eleResponse(element, *args)`` of each of ``elements``,
    summed over the nodes or elements and multiplied by ``scale``; in ``unit``.

    Values are what OpenSees gives, in the script's units times ``scale``: reactions
    (``ops.reactions()`` before they are read) are the supports' resisting forces, gravity
    included and damping forces not; ``nodeDisp`` includes the gravity state's
    displacement, ``nodeAccel`` is relative to the ground.
    """

    model_config = ConfigDict(extra="forbid")

    name: str = Field(
        pattern=r"^[A-Za-z_][A-Za-z0-9_.-]*$",
        description="the response's name (its dataset channel and EDP column)",
    )
    kind: Literal["nodeReaction", "nodeDisp", "nodeVel", "nodeAccel", "eleResponse"] = Field(
        description="the OpenSees command that gives it"
    )
    nodes: list[int] | None = Field(None, min_length=1, description="nodes, for a node kind")
    dof: int | None = Field(None, ge=1, description="the DOF of each node (from 1)")
    elements: list[int] | None = Field(None, min_length=1, description="elements, for eleResponse")
    args: list[str] = Field(
        ["force"], min_length=1, description="eleResponse's arguments (force, basicForce, ...)"
    )
    component: int = Field(1, ge=1, description="which value of eleResponse's (from 1)")
    unit: str = Field(min_length=1, description="the unit of the values after scale (kN, m)")
    scale: float = Field(1.0, description="factor on the sum (-1 to flip a sign)")
    description: str = Field("", description="what it is, in words")
    pelicun_type: str | None = Field(
        None,
        pattern=r"^[A-Z]{1,8}$",
        description="its peak's demand type in a pelicun demand sample (BRD, VB, ...); "
        "none: not written there",
    )
    pelicun_location: int = Field(1, ge=0, description="that demand's location")

    @model_validator(mode="after")
    def _complete(self) -> ResponseParams:
        if self.kind in NODE_KINDS:
            if self.nodes is None or self.dof is None or self.elements is not None:
                raise ValueError(f"response '{self.name}': {self.kind} needs nodes and dof")
        elif self.elements is None or self.nodes is not None:
            raise ValueError(f"response '{self.name}': eleResponse needs elements")
        return self

    def channel(self) -> ResponseChannel:
        """The dataset channel it is stored as."""
        return ResponseChannel(
            self.name, self.unit, self.description, self.pelicun_type, self.pelicun_location
        )


def check_responses(ops: Any, responses: tuple[ResponseParams, ...], script: Any) -> None:
    """Raise :class:`ScriptError` for a response naming a node, DOF or element the model
    built in ``ops`` lacks, or a component its element's response does not have."""
    nodes, elements = set(ops.getNodeTags()), set(ops.getEleTags())
    for response in responses:
        for node in response.nodes or ():
            if node not in nodes:
                raise ScriptError(
                    f"responses: '{response.name}' names node {node}, which the model of "
                    f"OpenSees script {script} does not have"
                )
            ndf = int(ops.getNDF(node)[0])
            if response.dof is not None and response.dof > ndf:
                raise ScriptError(
                    f"responses: '{response.name}': node {node} has DOFs 1 to {ndf}, not "
                    f"{response.dof}"
                )
        for element in response.elements or ():
            if element not in elements:
                raise ScriptError(
                    f"responses: '{response.name}' names element {element}, which the "
                    f"model of OpenSees script {script} does not have"
                )
            found = ops.eleResponse(element, *response.args)
            if len(found) < response.component:
                raise ScriptError(
                    f"responses: '{response.name}': eleResponse({element}, "
                    f"{', '.join(map(repr, response.args))}) gives {len(found)} values, not "
                    f"component {response.component}"
                )


def response_reader(ops: Any, responses: tuple[ResponseParams, ...]) -> Callable[[], list[float]]:
    """A function returning each response's value now (reactions formed first)."""
    react = any(r.kind == "nodeReaction" for r in responses)

    def value(response: ResponseParams) -> float:
        if response.kind in NODE_KINDS:
            command = getattr(ops, response.kind)
            total = sum(command(node, response.dof) for node in response.nodes)
        else:
            total = sum(
                ops.eleResponse(element, *response.args)[response.component - 1]
                for element in response.elements
            )
        return response.scale * total

    def read() -> list[float]:
        if react:
            ops.reactions()
        return [value(r) for r in responses]

    return read
