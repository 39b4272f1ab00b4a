"""The IR's statements beyond motion and I/O: what olp keeps but does not model.

Re-exported from :mod:`olp.ir` (``from olp.ir import Verbatim``). Like every IR node these are
frozen dataclasses with a ``span`` and a ``kind``, changed with ``dataclasses.replace``.

:class:`Verbatim` is the one vendor-specific node of the IR, on purpose: a statement a frontend
read, kept so that nothing is dropped, but whose meaning olp does not model (``$ACC.CP = 2.0``,
``ret = RSI_ON(#RELATIVE)``). A post of the same ``language`` writes its text unchanged; any
other post stops with an error naming the line. Passes treat it as taking no time and moving
nothing (which is the approximation: the controller may do more).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Literal, TypeAlias

from olp.span import GENERATED, SourceSpan

if TYPE_CHECKING:
    from olp.ir import Node


class FlowError(ValueError):
    """A flow node was made with values it cannot hold (raised at construction)."""


_LINE_BREAKS = frozenset("\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029")


@dataclass(frozen=True, slots=True, kw_only=True)
class Verbatim:
    """A statement kept as its source text: ``text`` (one line, as the source spells it, without
    its comment), the ``language`` it is written in (a frontend's language, ``"krl"``), and
    ``reason``: why olp does not model it.

    The text can never become more than one statement of the output: it must be one line
    without control characters (checked here, and again by the post that writes it).

    ``native_only``: the statement matters only on a controller of its own ``language`` and,
    where it stands, changes nothing olp models (no variable of the program, no motion, no
    motion setting a later motion relies on): the pendant's ``$BWDSTART = FALSE`` in each
    inline form, the standard lines of the pendant's INI fold before the first motion. A post
    of the same language writes it as any verbatim statement, except that the next motion need
    not write its settings again; any other post leaves it out with a warning giving
    ``reason`` (kind ``ignored``) instead of the error; passes treat it as absent. A statement
    that may change what olp models (a BAS with run-time values, ``$ACC.CP``) is never
    native-only: leaving it out would change what the robot does.

    ``modelled`` (with ``native_only``): the statement sets motion settings that olp modelled
    as the settings of a motion after it (a line of a FOR loop over ``$VEL_AXIS[i]`` that olp
    unrolled into those settings). Any other post leaves it out without a word: it writes
    that effect itself, with the motion. Its own post writes it, and writes every setting of
    the next motion again after it (as after any verbatim statement): the motion then runs
    with olp's values, the ones it checked, even where the statement's own differ in a way
    olp's model does not hold (a percent per axis, where olp keeps the smallest).
    """

    text: str
    language: str
    reason: str = ""
    native_only: bool = False
    modelled: bool = False
    span: SourceSpan = GENERATED
    kind: Literal["verbatim"] = field(default="verbatim", init=False)

    def __post_init__(self) -> None:
        if not self.text.strip():
            raise FlowError("Verbatim.text must hold a statement, got an empty text")
        bad = next((c for c in self.text if c in _LINE_BREAKS or (ord(c) < 32 and c != "\t")), None)
        if bad is not None:
            raise FlowError(f"Verbatim.text must be one line, found {bad!r} in {self.text!r}")
        if not self.language:
            raise FlowError("Verbatim.language must name the language of the text")
        if self.modelled and not self.native_only:
            raise FlowError("Verbatim.modelled needs native_only: its own post writes it")


# --------------------------------------------------------------------------------------------
# Expressions: what a condition, a bound or an assigned value says, vendor-neutral

BINARY_OPERATORS = frozenset(
    {
        "+",
        "-",
        "*",
        "/",
        "==",
        "<>",
        "<",
        "<=",
        ">",
        ">=",
        "and",
        "or",
        "xor",
        "bit_and",
        "bit_or",
        "bit_xor",
        "geometric",
    }
)
"""Operators of :class:`BinaryOp`. ``geometric`` is KUKA's ``:`` (frame composition); a post
without it stops on it with a located error."""
UNARY_OPERATORS = frozenset({"-", "+", "not", "bit_not"})


@dataclass(frozen=True, slots=True, kw_only=True)
class Constant:
    """A constant: ``bool``, ``int``, ``float`` or ``str``; ``enum``: the value names an
    enumeration member (KRL ``#BASE``), written by its own language only."""

    value: bool | int | float | str
    enum: bool = False
    span: SourceSpan = GENERATED


@dataclass(frozen=True, slots=True, kw_only=True)
class Name:
    """A variable (or constant) by name, as the program spells it."""

    name: str
    span: SourceSpan = GENERATED

    def __post_init__(self) -> None:
        if not self.name:
            raise FlowError("Name.name must not be empty")


@dataclass(frozen=True, slots=True, kw_only=True)
class Index:
    """``base[indices]``; an index left out (KRL ``TEXT[]``, ``NAME[1,]``) is None."""

    base: Expr
    indices: tuple[Expr | None, ...]
    span: SourceSpan = GENERATED


@dataclass(frozen=True, slots=True, kw_only=True)
class Member:
    """``base.field`` (a component of a structure: ``lPlace.Z``)."""

    base: Expr
    field: str
    span: SourceSpan = GENERATED


@dataclass(frozen=True, slots=True, kw_only=True)
class DigitalInput:
    """The state of digital input ``index`` (KRL ``$IN[n]``).

    ``signal``: the name the program reads the bit by where it has one (a KRL
    ``SIGNAL InTermicoCinta $IN[9]`` declared outside the program, in ``$config.dat``), so that
    a post of that language writes the program as it was written; None: by number. The name
    is only another spelling of ``index``: every other post, and every check, uses the number.
    """

    index: int
    signal: str | None = None
    span: SourceSpan = GENERATED


@dataclass(frozen=True, slots=True, kw_only=True)
class FunctionCall:
    """A call in an expression: ``name(args)``; an argument left out is None."""

    name: str
    args: tuple[Expr | None, ...] = ()
    span: SourceSpan = GENERATED


@dataclass(frozen=True, slots=True, kw_only=True)
class BinaryOp:
    op: str
    left: Expr
    right: Expr
    span: SourceSpan = GENERATED

    def __post_init__(self) -> None:
        if self.op not in BINARY_OPERATORS:
            raise FlowError(
                f"BinaryOp.op must be one of {sorted(BINARY_OPERATORS)}, got {self.op!r}"
            )


@dataclass(frozen=True, slots=True, kw_only=True)
class UnaryOp:
    op: str
    operand: Expr
    span: SourceSpan = GENERATED

    def __post_init__(self) -> None:
        if self.op not in UNARY_OPERATORS:
            raise FlowError(f"UnaryOp.op must be one of {sorted(UNARY_OPERATORS)}, got {self.op!r}")


@dataclass(frozen=True, slots=True, kw_only=True)
class Aggregate:
    """A structure value: ``{X 1, Y 2}`` as (member, value) pairs; ``type_name`` as written."""

    members: tuple[tuple[str, Expr], ...]
    type_name: str | None = None
    span: SourceSpan = GENERATED


Expr: TypeAlias = (
    Constant | Name | Index | Member | DigitalInput | FunctionCall | BinaryOp | UnaryOp | Aggregate
)


# --------------------------------------------------------------------------------------------
# Statements: data, waits, jumps


@dataclass(frozen=True, slots=True, kw_only=True)
class Declare:
    """Declare variable ``name`` of ``type_name`` (the language's type name: ``INT``, ``REAL``,
    ``BOOL``, ``CHAR``, ``FRAME``, ``E6POS``, ``E6AXIS``, a structure's name) with array
    ``dims`` (empty for a scalar), an optional initial ``value``; ``constant``: it never
    changes; ``exported``: visible to other modules (KRL ``GLOBAL``).

    ``scope`` says where the variable lives:

    * ``"routine"``: the routine's own variable (KRL ``DECL`` in a ``DEF``, RAPID routine data),
      made afresh on every run;
    * ``"module"``: the module's data (a KRL ``.dat`` data list): it keeps its value between
      runs, and ``value`` is the value it holds when the program is loaded;
    * ``"external"``: declared outside the program (another module's ``GLOBAL`` data, the
      controller's ``$config.dat``) and only used here: a post for the same controller refers to
      it without declaring it; ``value`` is None (it is not this program's to set).

    ``elements``: the initial values of single array elements that module data sets after the
    declaration (a KRL data list's ``aCount[2]=5``), as (indices, value) pairs in source order.
    """

    name: str
    type_name: str
    dims: tuple[Expr | None, ...] = ()
    value: Expr | None = None
    constant: bool = False
    exported: bool = False
    scope: Literal["routine", "module", "external"] = "routine"
    elements: tuple[tuple[tuple[Expr | None, ...], Expr], ...] = ()
    span: SourceSpan = GENERATED
    kind: Literal["declare"] = field(default="declare", init=False)

    def __post_init__(self) -> None:
        if self.scope not in ("routine", "module", "external"):
            raise FlowError(f"Declare.scope must be routine, module or external: {self.scope!r}")
        if self.scope == "external" and (self.value is not None or self.elements):
            raise FlowError(f"Declare {self.name}: an external variable has no value here")
        if self.elements and not self.dims:
            raise FlowError(f"Declare {self.name}: elements are given for an array only")


@dataclass(frozen=True, slots=True, kw_only=True)
class Assign:
    """``target = value``; ``target`` is a :class:`Name`, :class:`Index` or :class:`Member`."""

    target: Expr
    value: Expr
    span: SourceSpan = GENERATED
    kind: Literal["assign"] = field(default="assign", init=False)


@dataclass(frozen=True, slots=True, kw_only=True)
class WaitUntil:
    """Wait until ``condition`` holds (KRL ``WAIT FOR``)."""

    condition: Expr
    span: SourceSpan = GENERATED
    kind: Literal["wait_until"] = field(default="wait_until", init=False)


@dataclass(frozen=True, slots=True, kw_only=True)
class Label:
    """A jump target."""

    name: str
    span: SourceSpan = GENERATED
    kind: Literal["label"] = field(default="label", init=False)


@dataclass(frozen=True, slots=True, kw_only=True)
class Goto:
    """Jump to :class:`Label` ``label`` of the same routine."""

    label: str
    span: SourceSpan = GENERATED
    kind: Literal["goto"] = field(default="goto", init=False)


@dataclass(frozen=True, slots=True, kw_only=True)
class Exit:
    """Leave the innermost loop."""

    span: SourceSpan = GENERATED
    kind: Literal["exit"] = field(default="exit", init=False)


@dataclass(frozen=True, slots=True, kw_only=True)
class Return:
    """Leave the routine here (in the program's own body: end the program); ``value``: what a
    function (:attr:`Routine.returns`) gives back, None in a routine without a result."""

    value: Expr | None = None
    span: SourceSpan = GENERATED
    kind: Literal["return"] = field(default="return", init=False)


# --------------------------------------------------------------------------------------------
# Interrupts and path triggers
#
# The KRL these model, as KUKA System Software 8 describes it (Operating and Programming
# Instructions for System Integrators, "Interrupt programming" and "Path-related switching
# actions"; the manual itself was not at hand: units and reference points were checked against
# robot-forum.com thread 34556 "Trigger Questions" and real KR C4 programs):
#   INTERRUPT DECL Prio WHEN Event DO Subprogram  declares an interrupt whose number is also its
#     priority (1 highest; 3 is the pendant's standard $STOPMESS interrupt);
#   INTERRUPT ON|OFF|ENABLE|DISABLE [Prio]  acts on one interrupt, or on all without a number;
#   TRIGGER WHEN DISTANCE=0|1 DELAY=t DO Statement [PRIO=p]  runs Statement at the start (0) or
#     the end (1) point of the next motion, shifted by t ms (negative: earlier);
#   TRIGGER WHEN PATH=d [ONSTART] DELAY=t DO Statement [PRIO=p]  runs it d mm before (d < 0) or
#     after the end point of the next motion (from its start point with ONSTART).
# Statement is an assignment or a subprogram call; PRIO only goes with a call.

INTERRUPT_ACTIONS = frozenset({"on", "off", "enable", "disable"})


@dataclass(frozen=True, slots=True, kw_only=True)
class InterruptDecl:
    """Declare interrupt ``priority``: when ``condition`` becomes true (an edge, not a level),
    the program stops where it is and runs ``handler`` (a subprogram call), then goes on.

    ``priority`` (an int >= 1) both names the interrupt (:class:`InterruptSwitch` acts on it) and
    ranks it: a lower number is served first (KRL's convention). ``exported``: the declaration
    is valid in the routines the program calls too (KRL ``GLOBAL``). A declared interrupt is off
    until switched on. Passes treat the declaration, and the handler it may run, as taking no
    time: cycle times do not include interrupts.
    """

    priority: int
    condition: Expr
    handler: FunctionCall
    exported: bool = False
    span: SourceSpan = GENERATED
    kind: Literal["interrupt_decl"] = field(default="interrupt_decl", init=False)

    def __post_init__(self) -> None:
        if isinstance(self.priority, bool) or not isinstance(self.priority, int):
            raise FlowError(f"InterruptDecl.priority must be an int, got {self.priority!r}")
        if self.priority < 1:
            raise FlowError(f"InterruptDecl.priority must be >= 1, got {self.priority}")
        if not isinstance(self.handler, FunctionCall):
            raise FlowError("InterruptDecl.handler must be a FunctionCall (the routine it runs)")


@dataclass(frozen=True, slots=True, kw_only=True)
class InterruptSwitch:
    """Switch interrupt ``priority`` (None: every declared interrupt) ``on`` or ``off``
    (declaration kept), or ``disable`` / ``enable`` it (events are held while disabled and
    served when it is enabled again). Takes no time."""

    action: str
    priority: int | None = None
    span: SourceSpan = GENERATED
    kind: Literal["interrupt"] = field(default="interrupt", init=False)

    def __post_init__(self) -> None:
        if self.action not in INTERRUPT_ACTIONS:
            raise FlowError(
                f"InterruptSwitch.action must be one of {sorted(INTERRUPT_ACTIONS)}, "
                f"got {self.action!r}"
            )
        bad = self.priority is not None and (
            isinstance(self.priority, bool) or not isinstance(self.priority, int)
        )
        if bad or (self.priority is not None and self.priority < 1):
            raise FlowError(f"InterruptSwitch.priority must be an int >= 1, got {self.priority!r}")


@dataclass(frozen=True, slots=True, kw_only=True)
class PathTrigger:
    """Run ``action`` at a point of the next motion of the program (the controller attaches a
    trigger to the motion statement that follows it, whatever stands in between).

    The point is either ``at``: ``"start"`` or ``"end"`` of that motion (KRL ``DISTANCE=0|1``;
    with approximation the middle of the blend), or ``path`` metres from its end point (KRL
    ``PATH``; negative: before it; ``from_start``: from its start point instead, KRL
    ``ONSTART``). ``delay`` (s) shifts the point in time (negative: earlier).
    ``action`` is an :class:`Assign` or a :class:`FunctionCall` (a subprogram call);
    ``priority`` is a call's interrupt priority (KRL ``PRIO``; -1: the controller chooses),
    None for an assignment.

    Passes treat the trigger as taking no time and do not time its action: a cycle time never
    includes what a trigger starts.
    """

    action: Assign | FunctionCall
    at: str | None = None
    path: float | None = None
    from_start: bool = False
    delay: float = 0.0
    priority: int | None = None
    span: SourceSpan = GENERATED
    kind: Literal["trigger"] = field(default="trigger", init=False)

    def __post_init__(self) -> None:
        if (self.at is None) == (self.path is None):
            raise FlowError("PathTrigger needs exactly one of at ('start' or 'end') and path (m)")
        if self.at is not None and self.at not in ("start", "end"):
            raise FlowError(f"PathTrigger.at must be 'start' or 'end', got {self.at!r}")
        for name in ("path", "delay"):
            value = getattr(self, name)
            if value is not None and not (isinstance(value, int | float) and _finite(value)):
                raise FlowError(f"PathTrigger.{name} must be a finite number, got {value!r}")
        if self.from_start and self.path is None:
            raise FlowError("PathTrigger.from_start is for a path distance")
        if not isinstance(self.action, Assign | FunctionCall):
            raise FlowError("PathTrigger.action must be an Assign or a FunctionCall")
        if self.priority is not None and isinstance(self.action, Assign):
            raise FlowError("PathTrigger.priority is for a call; an assignment has none")


def _finite(value: float) -> bool:
    return bool(value == value and abs(value) != float("inf"))


# --------------------------------------------------------------------------------------------
# Routines: definitions, parameters and calls
#
# A program holds its own routines in :attr:`olp.ir.Program.routines`; a :class:`RoutineCall`
# in a body runs one of them. Checks and timing see a program with every call expanded
# (:func:`expand_calls`: each call site holds the routine's body, so every motion inside a
# routine is checked wherever it is called from).

PARAMETER_DIRECTIONS = frozenset({"in", "out"})


@dataclass(frozen=True, slots=True, kw_only=True)
class Parameter:
    """A routine's parameter ``name`` of ``type_name`` (the language's type name, as
    :class:`Declare` spells it; empty when the source does not say) with array ``dims``
    (empty for a scalar; an extent left open is None).

    ``direction``: ``"in"``, passed by value (the routine works on a copy; KRL ``:IN``);
    ``"out"``, passed by reference (the routine reads the caller's variable and its changes are
    the caller's: KRL ``:OUT``, and KRL's default when a parameter has no mark). A post that can
    pass only by value must refuse an ``"out"`` parameter, never pass it by value silently.

    ``head_dims``: how the source's routine head marks the parameter, where the language
    marks arrays there (KRL ``sText[]:IN`` 1, ``xPath[,]:OUT`` 2, ``nTool:IN`` 0; a head may mark
    fewer than the declaration has); None where no head said (a post of that language marks
    ``dims``). A post of the source's language writes the head as it was.
    """

    name: str
    type_name: str = ""
    dims: tuple[Expr | None, ...] = ()
    direction: str = "in"
    span: SourceSpan = GENERATED
    head_dims: int | None = None

    def __post_init__(self) -> None:
        if not self.name:
            raise FlowError("Parameter.name must not be empty")
        if self.direction not in PARAMETER_DIRECTIONS:
            raise FlowError(
                f"Parameter.direction must be one of {sorted(PARAMETER_DIRECTIONS)}, "
                f"got {self.direction!r}"
            )
        object.__setattr__(self, "dims", _tuple(self.dims))
        if self.head_dims is not None and self.head_dims < 0:
            raise FlowError(f"Parameter.head_dims must be 0 or more, got {self.head_dims}")

    @property
    def by_reference(self) -> bool:
        """Whether the caller's variable is passed (an ``"out"`` parameter)."""
        return self.direction == "out"


@dataclass(frozen=True, slots=True, kw_only=True)
class Routine:
    """A routine of the program: ``name``, ``params`` in call order, ``declarations`` (its
    local variables and constants, each a :class:`Declare`), ``body`` (nodes, like a
    program's), ``returns``: the type name of a function's result (KRL ``DEFFCT INT``; its
    array extents in ``returns_dims``), None for a routine without one; ``exported``: other
    modules may call it (KRL ``GLOBAL``).

    A function gives its result with :class:`Return` ``(value=...)`` and is called in an
    expression (:class:`FunctionCall`); a routine without a result is called with
    :class:`RoutineCall`.
    """

    name: str
    params: tuple[Parameter, ...] = ()
    declarations: tuple[Declare, ...] = ()
    body: tuple[Node, ...] = ()
    returns: str | None = None
    returns_dims: tuple[Expr | None, ...] = ()
    exported: bool = False
    span: SourceSpan = GENERATED
    kind: Literal["routine"] = field(default="routine", init=False)

    def __post_init__(self) -> None:
        if not self.name:
            raise FlowError("Routine.name must not be empty")
        for name in ("params", "declarations", "body", "returns_dims"):
            object.__setattr__(self, name, _tuple(getattr(self, name)))
        if any(not isinstance(p, Parameter) for p in self.params):
            raise FlowError(f"Routine {self.name}: params must be Parameter objects")
        if any(not isinstance(d, Declare) for d in self.declarations):
            raise FlowError(f"Routine {self.name}: declarations must be Declare statements")
        names = [p.name.casefold() for p in self.params]
        names += [d.name.casefold() for d in self.declarations]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise FlowError(f"Routine {self.name}: {twice[0]!r} is declared twice")

    @property
    def is_function(self) -> bool:
        """Whether the routine gives a result (:attr:`returns`)."""
        return self.returns is not None


@dataclass(frozen=True, slots=True, kw_only=True)
class RoutineCall:
    """Run routine ``name`` of the program (:attr:`olp.ir.Program.routines`) with ``args``,
    one per parameter in order (None: an argument left out). An argument for an ``"out"``
    parameter names the caller's variable (a :class:`Name`, :class:`Index` or
    :class:`Member`). A call of a routine the program does not hold (another module's, the
    controller's) is an :class:`olp.ir.Call`."""

    name: str
    args: tuple[Expr | None, ...] = ()
    span: SourceSpan = GENERATED
    kind: Literal["routine_call"] = field(default="routine_call", init=False)

    def __post_init__(self) -> None:
        if not self.name:
            raise FlowError("RoutineCall.name must not be empty")
        object.__setattr__(self, "args", _tuple(self.args))


@dataclass(frozen=True, slots=True, kw_only=True)
class Expanded:
    """A :class:`RoutineCall` with the body of the routine it runs, in the analysis view of a
    program (:func:`expand_calls`); not a node of a program as a frontend or a user makes it.

    Iterating a program walks into ``body`` as into any block, so that every instruction
    inside a routine has a step of its own at every call site; the call itself is not an
    instruction there (a post writes it as the call). A :class:`Return` in ``body`` ends the
    expansion, and its labels are its own (a label in a routine is not one of the caller's).

    ``entry``: not a call but a routine no call of the program runs (a library's, called from
    other modules or the PLC) that moves the robot, expanded after the program's end
    (:func:`expand_entries`) so that its motions are checked from where an unknown caller
    enters it: the robot where olp does not know. It is no part of the program's run: no
    predecessor of its motions, no part of the cycle time, not written as a call.
    """

    call: RoutineCall
    body: tuple[Node, ...]
    span: SourceSpan = GENERATED
    entry: bool = False
    kind: Literal["expanded"] = field(default="expanded", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "body", _tuple(self.body))


# --------------------------------------------------------------------------------------------
# Blocks


def _tuple(value: Any) -> tuple[Any, ...]:
    return value if isinstance(value, tuple) else tuple(value)


@dataclass(frozen=True, slots=True, kw_only=True)
class Branch:
    """One ``condition: body`` arm of an :class:`If`."""

    condition: Expr
    body: tuple[Node, ...]
    span: SourceSpan = GENERATED

    def __post_init__(self) -> None:
        object.__setattr__(self, "body", _tuple(self.body))


@dataclass(frozen=True, slots=True, kw_only=True)
class If:
    """``if / else if ... / else``: the first ``branches`` arm whose condition holds runs, else
    ``orelse``.

    ``has_else``: the source writes an else arm even where ``orelse`` is empty (a KRL ``ELSE``
    followed only by blank lines); a post of the source's own language writes it back, so a
    program read and written in one language keeps the line. An empty arm does nothing."""

    branches: tuple[Branch, ...]
    orelse: tuple[Node, ...] = ()
    has_else: bool = False
    span: SourceSpan = GENERATED
    kind: Literal["if"] = field(default="if", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "branches", _tuple(self.branches))
        object.__setattr__(self, "orelse", _tuple(self.orelse))
        if not self.branches:
            raise FlowError("If needs at least one branch")


@dataclass(frozen=True, slots=True, kw_only=True)
class Case:
    """One arm of a :class:`Switch`: runs when the subject equals one of ``values``."""

    values: tuple[Expr, ...]
    body: tuple[Node, ...]
    span: SourceSpan = GENERATED

    def __post_init__(self) -> None:
        object.__setattr__(self, "values", _tuple(self.values))
        object.__setattr__(self, "body", _tuple(self.body))


@dataclass(frozen=True, slots=True, kw_only=True)
class Switch:
    """``switch subject``: the first case with a matching value runs, else ``default``.

    ``has_default``: the source writes a default arm even where ``default`` is empty (see
    :attr:`If.has_else`)."""

    subject: Expr
    cases: tuple[Case, ...]
    default: tuple[Node, ...] = ()
    has_default: bool = False
    span: SourceSpan = GENERATED
    kind: Literal["switch"] = field(default="switch", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "cases", _tuple(self.cases))
        object.__setattr__(self, "default", _tuple(self.default))


@dataclass(frozen=True, slots=True, kw_only=True)
class While:
    """Run ``body`` while ``condition`` holds (tested before each pass)."""

    condition: Expr
    body: tuple[Node, ...]
    span: SourceSpan = GENERATED
    kind: Literal["while"] = field(default="while", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "body", _tuple(self.body))


@dataclass(frozen=True, slots=True, kw_only=True)
class Repeat:
    """Run ``body``, then again until ``until`` holds (at least once)."""

    body: tuple[Node, ...]
    until: Expr
    span: SourceSpan = GENERATED
    kind: Literal["repeat"] = field(default="repeat", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "body", _tuple(self.body))


@dataclass(frozen=True, slots=True, kw_only=True)
class Loop:
    """Run ``body`` for ever; only an :class:`Exit` (or a jump, or :class:`Return`) leaves."""

    body: tuple[Node, ...]
    span: SourceSpan = GENERATED
    kind: Literal["loop"] = field(default="loop", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "body", _tuple(self.body))


@dataclass(frozen=True, slots=True, kw_only=True)
class For:
    """``for variable = start to stop [step step]`` (both bounds included)."""

    variable: str
    start: Expr
    stop: Expr
    body: tuple[Node, ...]
    step: Expr | None = None
    span: SourceSpan = GENERATED
    kind: Literal["for"] = field(default="for", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "body", _tuple(self.body))


Block: TypeAlias = If | Switch | While | Repeat | Loop | For | Expanded
Statement: TypeAlias = (
    Declare
    | Assign
    | WaitUntil
    | Label
    | Goto
    | Exit
    | Return
    | InterruptDecl
    | InterruptSwitch
    | PathTrigger
    | RoutineCall
    | Verbatim
)
BLOCK_TYPES = (If, Switch, While, Repeat, Loop, For, Expanded)
FLOW_TYPES = (
    *BLOCK_TYPES,
    Declare,
    Assign,
    WaitUntil,
    Label,
    Goto,
    Exit,
    Return,
    InterruptDecl,
    InterruptSwitch,
    PathTrigger,
    RoutineCall,
)
"""Nodes of this module that are not ordinary instructions (:class:`Verbatim` is one: passes
and posts treat it like any other instruction)."""


# --------------------------------------------------------------------------------------------
# Walking and editing


def bodies(block: Block) -> tuple[tuple[Node, ...], ...]:
    """The bodies of a block, in source order (an If's branches then its else)."""
    if isinstance(block, If):
        return (*(b.body for b in block.branches), block.orelse)
    if isinstance(block, Switch):
        return (*(c.body for c in block.cases), block.default)
    return (block.body,)


def with_bodies(block: Block, new: Sequence[tuple[Node, ...]]) -> Block:
    """``block`` with its bodies replaced (same order as :func:`bodies`)."""
    if isinstance(block, If):
        arms = tuple(replace(b, body=body) for b, body in zip(block.branches, new, strict=False))
        return replace(block, branches=arms, orelse=new[-1])
    if isinstance(block, Switch):
        cases = tuple(replace(c, body=body) for c, body in zip(block.cases, new, strict=False))
        return replace(block, cases=cases, default=new[-1])
    return replace(block, body=new[0])


def leaves(nodes: Iterable[Any]) -> Iterator[Any]:
    """Every node that is not a block, in source order, descending into blocks: the
    instructions (and flow statements) as the program text lists them."""
    for node in nodes:
        if isinstance(node, BLOCK_TYPES):
            for body in bodies(node):
                yield from leaves(body)
        else:
            yield node


def has_flow(nodes: Iterable[Any]) -> bool:
    """Whether ``nodes`` hold any node of this module other than :class:`Verbatim`."""
    return any(isinstance(n, FLOW_TYPES) for n in leaves_and_blocks(nodes))


def leaves_and_blocks(nodes: Iterable[Any]) -> Iterator[Any]:
    """Every node, blocks included (a block before its bodies' nodes)."""
    for node in nodes:
        yield node
        if isinstance(node, BLOCK_TYPES):
            for body in bodies(node):
                yield from leaves_and_blocks(body)


def map_leaves(nodes: Sequence[Any], edit: Callable[[Any], list[Any]]) -> tuple[Any, ...]:
    """``nodes`` with every non-block node replaced by ``edit(node)`` (a list: empty deletes,
    several insert), blocks kept with their bodies edited the same way."""
    out: list[Any] = []
    for node in nodes:
        if isinstance(node, BLOCK_TYPES):
            out.append(with_bodies(node, [map_leaves(b, edit) for b in bodies(node)]))
        else:
            out.extend(edit(node))
    return tuple(out)


def sub_expressions(expr: Any) -> list[Any]:
    """The expressions directly inside ``expr`` (operands, index, base, arguments, members)."""
    if isinstance(expr, BinaryOp):
        return [expr.left, expr.right]
    if isinstance(expr, UnaryOp):
        return [expr.operand]
    if isinstance(expr, Index):
        return [expr.base, *(i for i in expr.indices if i is not None)]
    if isinstance(expr, Member):
        return [expr.base]
    if isinstance(expr, FunctionCall):
        return [a for a in expr.args if a is not None]
    if isinstance(expr, Aggregate):
        return [v for _, v in expr.members]
    return []


def walk_expression(expr: Any) -> Iterator[Any]:
    """``expr`` and every expression inside it, depth first."""
    yield expr
    for child in sub_expressions(expr):
        yield from walk_expression(child)


# --------------------------------------------------------------------------------------------
# The analysis view: calls expanded


def expand_calls(nodes: Sequence[Any], routines: Sequence[Routine]) -> tuple[Any, ...]:
    """``nodes`` with every :class:`RoutineCall` of one of ``routines`` (by name, any case)
    made an :class:`Expanded` holding that routine's body, expanded the same way; calls of
    other names are kept as they are.

    Raises :class:`FlowError` for a routine that calls itself, directly or through others
    (the chain and the call's place in the message): its expansion would never end.
    """
    table = {r.name.casefold(): r for r in routines}
    return _expand(tuple(nodes), table, ())


def _expand(
    nodes: tuple[Any, ...], table: dict[str, Routine], chain: tuple[str, ...]
) -> tuple[Any, ...]:
    out: list[Any] = []
    for node in nodes:
        if isinstance(node, BLOCK_TYPES):
            out.append(with_bodies(node, [_expand(b, table, chain) for b in bodies(node)]))
            continue
        routine = table.get(node.name.casefold()) if isinstance(node, RoutineCall) else None
        if routine is None:
            out.append(node)
            continue
        if routine.name.casefold() in chain:
            names = " -> ".join([*chain, routine.name])
            raise FlowError(
                f"{node.span.location}: {routine.name} calls itself ({names}); its calls cannot "
                "be expanded for checking"
            )
        body = _expand(routine.body, table, (*chain, routine.name.casefold()))
        out.append(Expanded(call=node, body=body, span=node.span))
    return tuple(out)


def expand_entries(nodes: Sequence[Any], routines: Sequence[Routine]) -> tuple[Any, ...]:
    """``nodes`` (calls already expanded, :func:`expand_calls`) with an entry
    (:attr:`Expanded.entry`) appended for each routine of ``routines`` that no expansion in
    ``nodes`` (nor an earlier entry) runs and whose body holds a motion, in the routines'
    order; its own calls of other routines expanded."""
    table = {r.name.casefold(): r for r in routines}
    out = list(nodes)
    ran = _expanded_names(out)
    for routine in routines:
        if routine.name.casefold() in ran or not _has_motion(routine.body):
            continue
        call = RoutineCall(name=routine.name, span=routine.span)
        body = _expand(routine.body, table, (routine.name.casefold(),))
        out.append(Expanded(call=call, body=body, span=routine.span, entry=True))
        ran |= {routine.name.casefold(), *_expanded_names(body)}
    return tuple(out)


def _expanded_names(nodes: Sequence[Any]) -> set[str]:
    return {n.call.name.casefold() for n in leaves_and_blocks(nodes) if isinstance(n, Expanded)}


def _has_motion(nodes: Sequence[Any]) -> bool:
    from olp.ir import LinearPath, RuntimeMove, is_motion  # (olp.ir builds on this module)

    return any(is_motion(n) or isinstance(n, RuntimeMove | LinearPath) for n in leaves(nodes))


def inline_expansions(nodes: Sequence[Any]) -> tuple[Any, ...]:
    """``nodes`` with every :class:`Expanded` replaced by its body, in place: one body without
    routines, for a writer that does not write them. Instructions keep their order (the step
    of each stays its step). An entry (:attr:`Expanded.entry`) is no part of the program's
    run: left out."""
    out: list[Any] = []
    for node in nodes:
        if isinstance(node, Expanded) and node.entry:
            continue
        if isinstance(node, Expanded):
            out.extend(inline_expansions(node.body))
        elif isinstance(node, BLOCK_TYPES):
            out.append(with_bodies(node, [inline_expansions(b) for b in bodies(node)]))
        else:
            out.append(node)
    return tuple(out)
