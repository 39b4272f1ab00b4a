"""Motions to run-time targets (:class:`olp.ir.RuntimeMove`) in the posts whose language names a
target by a variable: which expressions a post may write as a motion's target.

KRL writes the expression back as it stands (:mod:`olp.posts.kuka`). Another language can name
only a *pose variable the post declares*: a variable of the program (or an element of one of its
arrays) whose type the post's flow writer maps to the language's position type (RAPID
``robtarget``/``jointtarget``: :mod:`olp.posts.rapid_flow`). Anything else (a function's
result, an aggregate with run-time members, a controller variable, a name declared in another
module or in the controller's ``$config.dat``) is an error naming the line: the post cannot
know what the language would call it, and never guesses. Every name is written through the
post's own spelling and checks (the flow writer's ``name``), so user text never becomes code.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from olp import ir
from olp.ir_flow import leaves_and_blocks
from olp.posts.flow_text import FlowProblem, Symbols

POSE_KINDS = frozenset({"cartesian", "joints"})
"""Value kinds (:data:`olp.posts.flow_text.KRL_KINDS`) of positions: Cartesian, joints."""


def program_nodes(program: ir.Program) -> list[Any]:
    """The nodes whose declarations name the program's variables: its own, and each routine's
    parameters (of a known type) and local declarations."""
    nodes: list[Any] = list(leaves_and_blocks(program.instructions))
    for routine in program.routines:
        nodes += [
            ir.Declare(name=p.name, type_name=p.type_name, dims=p.dims, span=p.span)
            for p in routine.params
            if p.type_name
        ]
        nodes += [*routine.declarations, *leaves_and_blocks(routine.body)]
    return nodes


def pose_kind(expr: ir.Expr, symbols: Symbols, language: str) -> str:
    """The value kind (``"cartesian"`` or ``"joints"``) of the pose variable ``expr`` names: a
    :class:`~olp.ir.Name` of a declared variable, or an :class:`~olp.ir.Index` of one of its
    arrays with one index per dimension. A :class:`~olp.posts.flow_text.FlowProblem` says why
    anything else cannot be a ``language`` target."""
    base = expr.base if isinstance(expr, ir.Index) else expr
    if not isinstance(base, ir.Name):
        raise FlowProblem(
            f"{language} names a run-time target by a pose variable (or an element of an "
            "array of them); olp does not write this expression as one"
        )
    var = symbols.variable(base.name)
    if var is None:
        raise FlowProblem(
            f"{base.name} is not declared in the program (another module's data, or the "
            f"controller's $config.dat): olp cannot tell what {language} calls it"
        )
    if var.kind not in POSE_KINDS:
        raise FlowProblem(f"{base.name} is not a position ({var.declare.type_name})")
    indices = expr.indices if isinstance(expr, ir.Index) else ()
    if len(indices) != len(var.dims) or any(i is None for i in indices):
        raise FlowProblem(
            f"{base.name} has {len(var.dims)} dimension(s): a target is one position of it"
        )
    return var.kind


def targets(ins: ir.RuntimeMove) -> Iterable[ir.Expr]:
    """The expressions a run-time motion moves to: its via point (an arc's), then its target."""
    return (ins.target,) if ins.via is None else (ins.via, ins.target)
