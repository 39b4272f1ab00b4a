"""The module's own routines in the IR: each call lowered in place, then kept as a call.

The statement walk (:mod:`olp.frontends.krl.lower`) lowers the body of a called ``DEF`` at every
call, from the state there (the values of its parameters, the motion settings, the position),
and wraps what it lowered in a :class:`PendingCall`. :func:`assemble` then decides per routine:

* when every call lowered the routine to the same IR (same statements, same motions with the
  same targets, speeds, tools and frames), the routine becomes one :class:`olp.ir.Routine` and
  each call an :class:`olp.ir.RoutineCall`; checks and timing see its body at every call site
  (:meth:`olp.ir.Program.expanded`);
* when the calls differ only in statements that are not motions (``$OUT[nSlot] = TRUE`` is a
  numbered output at each call), the routine is lowered at a call once more with its
  parameters unknown (``$OUT[nSlot] = TRUE`` kept as written); if that body is the same at every
  call and moves the robot as each call does, it is the routine;
* otherwise one routine text cannot say what the calls do (``LIN pTarget`` to a parameter that
  is another point at each call, a routine that runs with the caller's ``$TOOL``), and the
  routine is written out at each call, as olp did before it kept routines, with a warning that
  names the first statement that differs and two calls that differ there.

Routines no call reaches (interrupt handlers, functions, a library's routines that other
modules or the PLC call) are lowered once on their own by :mod:`olp.frontends.krl.lower`, from
what olp knows where an unknown caller enters them (parameters unknown, every motion setting
the controller's, the robot where olp does not know): a plain motion in one runs with the
controller's settings, an inline form's is modelled; the checks take such a routine from an
unknown start (:attr:`olp.ir_flow.Expanded.entry`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

from olp import ir
from olp.frontends.krl.ast import IgnoredLine, Routine, SourceSet
from olp.ir_flow import leaves, map_leaves


@dataclass(frozen=True, slots=True, kw_only=True)
class PendingCall:
    """A call of a routine of the module with the body its lowering gave at this call."""

    call: ir.RoutineCall
    body: tuple[Any, ...]
    generic: tuple[Any, ...] | None
    span: ir.SourceSpan
    kind: Literal["pending_call"] = field(default="pending_call", init=False)


def calls_in(nodes: Sequence[Any]) -> Iterator[PendingCall]:
    """Every :class:`PendingCall` in ``nodes``, those in lowered bodies included, in order."""
    for node in leaves(nodes):
        if isinstance(node, PendingCall):
            yield node
            yield from calls_in(node.body)


def moves(nodes: Sequence[Any]) -> bool:
    """Whether ``nodes`` (or a routine they call) hold a motion (one to a run-time target
    too: it runs with the settings in effect where it runs)."""
    for node in leaves(nodes):
        if ir.is_motion(node) or isinstance(node, ir.LinearPath | ir.RuntimeMove):
            return True
        if isinstance(node, PendingCall) and moves(node.body):
            return True
    return False


@dataclass
class Assembled:
    """The program's body and routines, and the warnings about routines written out."""

    instructions: tuple[Any, ...]
    routines: tuple[ir.Routine, ...]
    ignored: list[IgnoredLine]


def assemble(
    main: tuple[Any, ...],
    alone: dict[str, tuple[Any, ...]],
    table: dict[str, Routine],
    sources: SourceSet,
    entered: Callable[[str, Sequence[int]], tuple[Any, ...] | None] | None = None,
) -> Assembled:
    """The program from the main body ``main`` and the bodies ``alone`` of the routines lowered
    on their own (upper-case name -> body), ``table`` the module's routines by upper-case
    name (see the module docstring). ``entered``: a routine (upper-case name) lowered from an
    unknown caller's state for the calls at the lines given, None where olp cannot: the one
    text of calls that differ only in why a motion runs with the controller's settings."""
    found: dict[str, list[PendingCall]] = {}
    for call in calls_in([*main, *(n for body in alone.values() for n in body)]):
        found.setdefault(call.call.name.upper(), []).append(call)
    kept, ignored = set(alone), []
    bodies = dict(alone)
    for name, calls in found.items():
        differ = _first_difference(calls)
        generic = _generic(calls)
        if differ is None:
            kept.add(name)
            bodies[name] = calls[0].body
        elif generic is not None:
            kept.add(name)
            bodies[name] = generic
        elif (unknown := _entered_text(name, calls, entered)) is not None:
            kept.add(name)
            bodies[name] = unknown
        else:
            routine = table[name]
            reason = _written_out(routine, len(calls), *differ)
            ignored.append(IgnoredLine(routine.span, sources.snippet(routine.span), reason))

    def resolve(nodes: Sequence[Any]) -> tuple[Any, ...]:
        def edit(node: Any) -> list[Any]:
            if not isinstance(node, PendingCall):
                return [node]
            if node.call.name.upper() in kept:
                return [node.call]
            # Written out in place: its own RETURN ends the routine, not the caller.
            _refuse_nested_return(node, table[node.call.name.upper()], sources)
            return [n for n in resolve(node.body) if not isinstance(n, ir.Return)]

        return map_leaves(nodes, edit)

    routines = tuple(
        _routine(routine, resolve(bodies[name]), sources)
        for name, routine in table.items()
        if name in bodies
    )
    return Assembled(resolve(main), routines, ignored)


def _refuse_nested_return(node: PendingCall, routine: Routine, sources: SourceSet) -> None:
    """A RETURN inside a block of a routine written out at its calls would end the caller
    there (a RETURN on the body's own level, last, is dropped): a located error."""
    top = {id(n) for n in node.body if isinstance(n, ir.Return)}
    returns = (n for n in leaves(node.body) if isinstance(n, ir.Return) and id(n) not in top)
    nested = next(returns, None)
    if nested is not None:
        raise sources.error(
            f"RETURN inside a block of {routine.name}, which olp writes out at each of its "
            "calls (one routine text cannot say what every call does): written out, the RETURN "
            "would end the caller",
            nested.span,
            "make the calls agree (the same targets and motion settings at each call), or "
            "end the routine without a RETURN in a block",
        )


def _first_difference(calls: Sequence[PendingCall]) -> tuple[Any, PendingCall, PendingCall] | None:
    """The first node where a call's body differs from the first call's, with the two calls;
    None when every call lowered the same body."""
    first = calls[0]
    for other in calls[1:]:
        if other.body == first.body:
            continue
        mine, theirs = list(_flat(first.body)), list(_flat(other.body))
        for a, b in zip(mine, theirs, strict=False):
            if a != b:
                return a, first, other
        return (mine or theirs)[-1], first, other
    return None


def _generic(calls: Sequence[PendingCall]) -> tuple[Any, ...] | None:
    """The body lowered with the parameters unknown, when it is the same at every call and
    moves the robot exactly as each call's own lowering does (the calls differ only in what
    is not a motion: ``$OUT[nSlot] = bOpen`` kept as written instead of a numbered output);
    else None."""
    first = calls[0].generic
    if first is None or any(c.generic != first for c in calls[1:]):
        return None
    motions = [n for n in _flat(first) if ir.is_motion(n)]
    if any([n for n in _flat(c.body) if ir.is_motion(n)] != motions for c in calls):
        return None
    return first


def _entered_text(
    name: str,
    calls: Sequence[PendingCall],
    entered: Callable[[str, Sequence[int]], tuple[Any, ...] | None] | None,
) -> tuple[Any, ...] | None:
    """The routine lowered from an unknown caller's state (``entered``) where every call's
    body is that text, but for why its motions run with the controller's settings (a
    ``MovPlcSck()`` after ``Pattern(...)``, a routine olp did not read, at each call: the
    calls say which call of ``Pattern``, the text says the callers'); else None."""
    if entered is None or not any(
        isinstance(n, ir.RuntimeMove) and n.controller_settings for n in _flat(calls[0].body)
    ):
        return None
    unknown = entered(name, sorted({c.span.line for c in calls}))
    if unknown is None:
        return None
    text = _text(unknown)
    return unknown if all(_text(c.body) == text for c in calls) else None


def _text(nodes: Sequence[Any]) -> tuple[Any, ...]:
    """``nodes`` as the routine's text: a motion with the controller's settings without why
    (and without olp's settings, which the posts do not write for it), a call with its body."""

    def edit(node: Any) -> list[Any]:
        if isinstance(node, ir.RuntimeMove) and node.controller_settings:
            blank = ir.RuntimeMove(motion=node.motion, target=node.target, span=node.span)
            return [
                dataclasses.replace(
                    node,
                    reason="",
                    speed=blank.speed,
                    zone=blank.zone,
                    tool=blank.tool,
                    frame=blank.frame,
                )
            ]
        if isinstance(node, PendingCall):
            return [(node.call, _text(node.body))]
        return [node]

    return map_leaves(nodes, edit)


def _flat(nodes: Sequence[Any]) -> Iterator[Any]:
    for node in leaves(nodes):
        if isinstance(node, PendingCall):
            yield from _flat(node.body)
        elif isinstance(node, ir.LinearPath):
            yield from node
        else:
            yield node


def _written_out(routine: Routine, count: int, node: Any, a: PendingCall, b: PendingCall) -> str:
    what = _difference(node)
    return (
        f"{routine.kind} {routine.name} is written out at each of its {count} calls instead of "
        f"as a routine: {what} at line {node.span.line} differs between the calls at lines "
        f"{a.span.line} and {b.span.line} (the caller's values there), and one routine text "
        "holds one"
    )


def _difference(node: Any) -> str:
    if ir.is_motion(node):
        return "the motion's target, speed, zone, tool or base"
    return f"the {node.kind.replace('_', ' ')} statement"


def typed_params(
    routine: Routine, body: Sequence[Any]
) -> tuple[tuple[ir.Parameter, ...], list[Any]]:
    """``routine``'s parameters (:class:`olp.ir.Parameter`), typed by the declarations of
    their names at the top of ``body`` (KRL declares a parameter's type in the body:
    ``DEF Move(nBase:IN)`` then ``DECL INT nBase``), and ``body`` without those declarations.
    A parameter without a mark is KRL's ``:OUT`` (by reference). Used for the module's routines
    and for the program itself (``DEF MoveSettings(nBase:IN, nTool:IN)``, a module others call).
    """
    names = {p.name.upper() for p in routine.params}
    types: dict[str, ir.Declare] = {}
    rest: list[Any] = []
    for node in body:
        if isinstance(node, ir.Declare) and node.name.upper() in names:
            types.setdefault(node.name.upper(), node)
        else:
            rest.append(node)
    params = []
    for p in routine.params:
        decl = types.get(p.name.upper())
        params.append(
            ir.Parameter(
                name=p.name,
                type_name="" if decl is None else decl.type_name,
                dims=() if decl is None else decl.dims,
                direction="in" if p.direction == "IN" else "out",
                span=routine.span if decl is None else decl.span,
                head_dims=p.head_dims,
            )
        )
    return tuple(params), rest


def _routine(routine: Routine, body: tuple[Any, ...], sources: SourceSet) -> ir.Routine:
    """The IR routine: declarations of parameters give their types, the other declarations
    at the top of the body are its locals."""
    from olp.frontends.krl.flow import to_expr

    parameters, nodes = typed_params(routine, body)
    local: list[ir.Declare] = []
    rest: list[Any] = []
    for node in nodes:
        if isinstance(node, ir.Declare) and not any(
            d.name.upper() == node.name.upper() for d in local
        ):
            local.append(node)
        elif not isinstance(node, ir.Declare):
            rest.append(node)
    dims = tuple(to_expr(d, lambda _: None) for d in routine.returns_dims)
    return ir.Routine(
        name=routine.name,
        params=parameters,
        declarations=tuple(local),
        body=tuple(rest),
        returns=routine.returns,
        returns_dims=dims,
        exported=routine.exported,
        span=routine.span,
    )
