"""KRL data lists (``DEFDAT ... ENDDAT``): a module's ``.dat`` and the controller's ``$config.dat``.

A data list declares variables with values: the points the pendant taught
(``DECL E6POS XP1={X ..,S 6,T 27,...}``), the inline forms' motion data (``DECL PDAT PPDAT1``,
``LDAT``, ``FDAT``), and in ``$config.dat`` the tool and base tables (``TOOL_DATA[1]={X ..}``,
``TOOL_NAME[1,]="Gripper"``), ``XHOME``, ``FHOME``, ``PDEFAULT`` and signal names. olp reads
declarations, value assignments and one-bit ``SIGNAL`` names; other statements a data list may
hold (``EXT``, ``STRUC``, ``ENUM``, ...) are listed as ignored with the reason. Anything that
does not belong in a data list (motions, calls, control flow) is an error.

:class:`DataOps` does declarations and assignments of program variables for both data lists and
routines, so both follow the same rules.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

from olp import ir
from olp.errors import ParseError
from olp.frontends.krl.ast import (
    Assign,
    DatBlock,
    Decl,
    DeclItem,
    IgnoredLine,
    Index,
    Module,
    Other,
    SignalDecl,
    Source,
    SourceSet,
    Stmt,
    Text,
    Var,
)
from olp.frontends.krl.parse import gc_paused, parse_module
from olp.frontends.krl.values import (
    NOT_SET,
    ArrayValue,
    ElementKey,
    Evaluator,
    Signal,
    Unknown,
    Value,
    Variables,
    assign_path,
    with_type,
)

OTHER_REASONS = {
    "EXT": "external declarations are not needed by olp",
    "STRUC": "type definitions are not needed: olp reads values by their member names",
    "ENUM": "type definitions are not needed: olp reads enumeration values by name",
    "label": "jump labels are not lowered (GOTO is not supported)",
    "HALT": "HALT (stop until restarted) has no IR equivalent",
    "EXIT": "EXIT only matters inside a loop",
    "CONTINUE": "CONTINUE only affects the controller's advance run",
    "BRAKE": "BRAKE only matters in interrupt routines",
    "RESUME": "RESUME (leave an interrupt routine) has no IR equivalent",
    "ON_ERROR_PROCEED": "ON_ERROR_PROCEED (ignore the next statement's error) is not modelled",
}


@dataclass(frozen=True, slots=True, kw_only=True)
class KrlData:
    """What olp read from one data list: its name, variables and the lines it ignored.

    Read one with :func:`olp.frontends.krl.load_config_dat` (or :func:`read_data_list`) and pass
    it to :func:`olp.frontends.krl.load_krl` for as many programs as need it.
    """

    name: str
    filename: str
    values: Mapping[str, Value]
    ignored: tuple[IgnoredLine, ...]
    source: Source
    public: bool = False
    declared_at: Mapping[str, ir.SourceSpan] = field(default_factory=dict)
    global_names: frozenset[str] = frozenset()
    declarations: Mapping[str, tuple[Decl, DeclItem]] = field(default_factory=dict)
    """Name (upper case) -> the declaration and its item, for the program's module data
    (:mod:`olp.frontends.krl.module_data`)."""
    elements: Mapping[str, tuple[Assign, ...]] = field(default_factory=dict)
    """Name (upper case) -> the assignments of single elements of that array in the list
    (``aCount[2]=5``), in order."""
    types: tuple[tuple[str, ir.SourceSpan], ...] = ()
    """The list's type definitions (``GLOBAL STRUC MyType INT a, REAL b``, ``ENUM ...``) as
    written, with their spans, in order: the module's own are written back to its ``.dat``
    (:mod:`olp.frontends.krl.module_data`)."""

    def names(self) -> tuple[str, ...]:
        """The declared names (upper case), in the order they were read."""
        return tuple(self.values)

    def exported(self) -> tuple[str, ...]:
        """The names other modules see: those declared ``GLOBAL`` in a ``DEFDAT ... PUBLIC``
        (:func:`visible_globals` gives the rule and its source)."""
        if not self.public:
            return ()
        return tuple(n for n in self.values if n in self.global_names)


class DataOps:
    """Declarations, assignments and SIGNALs of program variables (for .dat files and routines).

    Methods return None when the statement was read, else the reason it was not (the caller
    lists the statement as ignored).
    """

    def __init__(self, variables: Variables, evaluator: Evaluator, sources: SourceSet) -> None:
        self.variables = variables
        self.evaluator = evaluator
        self.sources = sources

    def declare(
        self, decl: Decl, into: Callable[[str, Value], None], local: bool = False
    ) -> str | None:
        """Each item gets its value (or :class:`Unknown` when it has none: ``missing`` for a
        ``local`` variable of a routine, which nothing but the routine itself can set)."""
        missing = []
        for item in decl.items:
            name = item.name.upper()
            if item.dims is not None and item.value is None:
                into(name, ArrayValue(decl.type_name, {}, item.span))
                continue
            if item.value is None:
                if not self.variables.is_param(name):
                    missing.append(item.name)
                where = f"{item.span.location}"
                unset = local and not self.variables.is_param(name)
                into(
                    name,
                    Unknown(f"{item.name} is declared at {where} without a value", missing=unset),
                )
                continue
            value = self.evaluator.evaluate(item.value)
            into(name, value if isinstance(value, Unknown) else with_type(value, decl.type_name))
        if missing:
            return (
                f"declares {', '.join(missing)} without a value (olp knows a value only once "
                "the program assigns a constant)"
            )
        return None

    def assign(self, stmt: Assign) -> str | None:
        """``name[...].field = value`` with a constant value; else the variable becomes unknown."""
        target = stmt.target
        name = target.name.upper()
        if target.selectors and not self.variables.is_declared(name):
            elsewhere = self.variables.lookup(name)
            if isinstance(elsewhere, Unknown) and not elsewhere.missing:
                # A part of a record or array declared in a file olp was not given: the parts
                # the program does not assign are that file's, known only when it runs.
                self._forget(name, stmt, elsewhere)
                return f"the rest of {target.name} is not known: {elsewhere.reason}"
        value = self.evaluator.evaluate(stmt.value)
        keys = self._keys(target)
        for unknown in (value, keys):
            if isinstance(unknown, Unknown):
                self._forget(name, stmt, unknown)
                return f"the value is not constant: {unknown.reason}"
        assert not isinstance(value, Unknown) and not isinstance(keys, Unknown)
        old = self.variables.lookup(name) if self.variables.is_declared(name) else NOT_SET
        new = assign_path(old, target.selectors, value, keys, stmt.span)
        if isinstance(new, Unknown) and target.selectors:
            self._forget(name, stmt, new)
            return f"{new.reason}; {target.name} is unknown from here on"
        self.variables.assign(name, new)
        return None

    def _keys(self, target: Var) -> list[ElementKey] | Unknown:
        keys: list[ElementKey] = []
        for selector in target.selectors:
            if isinstance(selector, Index):
                key = self.evaluator.index_key(selector)
                if isinstance(key, Unknown):
                    return key
                keys.append(key)
        return keys

    def _forget(self, name: str, stmt: Assign, why: Unknown) -> None:
        """``name`` is unknown from here on; the reason says where and why (with its hint)."""
        value = self.sources.snippet(stmt.value.span)
        message = f"{stmt.target.name} was assigned {value!r} at {stmt.span.location}"
        self.variables.assign(name, Unknown(f"{message}, and {why.reason}", why.hint, why.missing))

    def signal(self, stmt: SignalDecl, into: Callable[[str, Value], None]) -> str | None:
        """``SIGNAL name $OUT[n]``: the name stands for that one bit from here on."""
        first = stmt.first
        if stmt.last is not None or not (isinstance(first, Var) and first.key in _IO_KEYS):
            into(stmt.name, Unknown(f"SIGNAL {stmt.name} is not a single $IN/$OUT bit"))
            return "only one-bit SIGNALs of $IN[n] / $OUT[n] are read"
        key = self._keys(first)
        index = None if isinstance(key, Unknown) else as_int_key(key)
        if index is None:
            into(stmt.name, Unknown(f"SIGNAL {stmt.name} has no constant index"))
            return "the SIGNAL's index is not a constant"
        into(stmt.name, Signal(first.name.upper(), index, stmt.span))
        return None


_IO_KEYS = frozenset({"$IN[]", "$OUT[]"})


def as_int_key(keys: list[ElementKey]) -> int | None:
    """The index of ``$OUT[n]`` from its evaluated keys."""
    if len(keys) == 1 and len(keys[0]) == 1 and isinstance(keys[0][0], int):
        return keys[0][0]
    return None


# ------------------------------------------------------------------------------------------------
# Reading a data list


def read_data_list(text: str, filename: str) -> KrlData:
    """Read the one ``DEFDAT ... ENDDAT`` of ``text``; :class:`ParseError` if it is not one."""
    source = Source.of(text, filename)
    with gc_paused():
        module = parse_module(source, fast=False)
    block = _the_data_block(module, source)
    return _read_block(block, source)


def _the_data_block(module: Module, source: Source) -> DatBlock:
    blocks = [item for item in module.items if isinstance(item, DatBlock)]
    for item in module.items:
        if not isinstance(item, DatBlock):
            name = os.path.basename(source.filename)
            message = f"{item.kind} {item.name} in a data list: {name} must hold DEFDAT ... ENDDAT"
            raise source.error(message, item.span)
    if len(blocks) != 1:
        line, column = source.last_position() if not blocks else (blocks[1].span.line, 1)
        span = ir.SourceSpan(source.filename, line, column)
        raise source.error("a data list holds exactly one DEFDAT ... ENDDAT", span)
    return blocks[0]


def _read_block(block: DatBlock, source: Source) -> KrlData:
    sources = SourceSet([source])
    base = os.path.basename(source.filename)

    def missing(name: str) -> Unknown:
        return Unknown(f"{name} is not declared in {base} before this line", missing=True)

    values: dict[str, Value] = {}
    variables = Variables(values, missing)
    ops = DataOps(variables, Evaluator(variables, sources.snippet), sources)
    ignored: list[IgnoredLine] = []
    declared_at: dict[str, ir.SourceSpan] = {}
    global_names: set[str] = set()

    def store(name: str, value: Value) -> None:
        values[name] = value

    declarations: dict[str, tuple[Decl, DeclItem]] = {}
    elements: dict[str, tuple[Assign, ...]] = {}
    types: list[tuple[str, ir.SourceSpan]] = []
    for stmt in block.body:
        if isinstance(stmt, Other) and stmt.kind in _TYPE_DEFINITIONS:
            types.append((sources.snippet(stmt.span), stmt.span))
        if isinstance(stmt, Decl):
            names = [item.name.upper() for item in stmt.items]
            declared_at.update((n, item.span) for n, item in zip(names, stmt.items, strict=True))
            pairs = zip(names, stmt.items, strict=True)
            declarations.update((n, (stmt, item)) for n, item in pairs)
            global_names.update(names if stmt.is_global else ())
        elif (
            isinstance(stmt, Assign)
            and stmt.target.name.upper() in declarations
            and len(stmt.target.selectors) == 1
            and isinstance(stmt.target.selectors[0], Index)
        ):
            name = stmt.target.name.upper()
            elements[name] = (*elements.get(name, ()), stmt)
        elif isinstance(stmt, SignalDecl):
            declared_at[stmt.name] = stmt.span
            global_names.update([stmt.name] if stmt.is_global else [])
        reason = _read_statement(stmt, ops, store, sources)
        if reason is not None:
            ignored.append(IgnoredLine(stmt.span, sources.snippet(stmt.span), reason))
    return KrlData(
        name=block.name,
        filename=source.filename,
        values=values,
        ignored=tuple(ignored),
        source=source,
        public=block.public,
        declared_at=declared_at,
        global_names=frozenset(global_names),
        declarations=declarations,
        elements=elements,
        types=tuple(types),
    )


# ------------------------------------------------------------------------------------------------
# Names other modules declare


def visible_globals(
    config: KrlData | None, shared: Sequence[KrlData], dat: KrlData | None
) -> dict[str, Value]:
    """The global variables a module sees, as the controller finds them: every name of
    ``$config.dat``, the ``GLOBAL`` names of the ``PUBLIC`` data lists in ``shared``, then the
    module's own ``.dat``, whose names hide global ones of the same name.

    KRL's rule (KUKA, KSS 8.x expert programming / system integrator manuals, "global data
    lists"; recalled, the text was not found to quote): a variable of a data list is visible to
    other modules only when the list is declared ``DEFDAT name PUBLIC`` *and* the variable
    ``DECL GLOBAL``; ``$CONFIG.DAT`` is the controller's global data list, whose declarations are
    global without the keyword; a module's own names hide global ones. A global name declared
    twice (in two lists, or in the module's own ``PUBLIC`` list and another) is refused by the
    controller: here a :class:`ParseError` at the second declaration naming the first.
    """
    values: dict[str, Value] = {}
    owner: dict[str, KrlData] = {}
    publishers = [(config, config.names())] if config is not None else []
    publishers += [(data, data.exported()) for data in shared]
    publishers += [(dat, dat.exported())] if dat is not None else []
    for data, names in publishers:
        for name in names:
            if name in owner and owner[name] is not data:
                raise _declared_twice(name, owner[name], data)
            owner[name] = data
            values[name] = data.values[name]
    if dat is not None:
        values.update(dat.values)
    return values


def _declared_twice(name: str, first: KrlData, second: KrlData) -> ParseError:
    span = second.declared_at.get(name, ir.SourceSpan(second.filename, 1, 1))
    where = first.declared_at.get(name, ir.SourceSpan(first.filename, 1, 1))
    return second.source.error(
        f"{name} is declared GLOBAL twice: at {where.location} and here",
        span,
        hint="the controller refuses a global name declared in two data lists; rename one, or "
        "give olp only the data lists the controller holds",
    )


def _read_statement(
    stmt: Stmt, ops: DataOps, store: Callable[[str, Value], None], sources: SourceSet
) -> str | None:
    if isinstance(stmt, Decl):
        return ops.declare(stmt, store)
    if isinstance(stmt, Assign):
        return ops.assign(stmt)
    if isinstance(stmt, SignalDecl):
        return ops.signal(stmt, store)
    if isinstance(stmt, Other) and stmt.kind in _DATA_LIST_OTHERS:
        return OTHER_REASONS[stmt.kind]
    raise _not_data(stmt, sources)


_TYPE_DEFINITIONS = frozenset({"STRUC", "ENUM"})
_DATA_LIST_OTHERS = frozenset({"EXT", *_TYPE_DEFINITIONS})
"""Statements a data list may hold that olp does not need."""


def _not_data(stmt: Stmt, sources: SourceSet) -> ParseError:
    found = sources.snippet(stmt.span)
    return sources.error(
        f"{found!r} does not belong in a data list",
        stmt.span,
        hint="a DEFDAT holds declarations (DECL ...), value assignments and SIGNALs",
    )


def text_value(value: Value) -> str | None:
    """The string of a CHAR array row or string constant, without padding, if it has one."""
    if isinstance(value, Text):
        return value.value.strip() or None
    return None
