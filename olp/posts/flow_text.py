"""Control flow and data for posts whose language is not the program's own: what RAPID and
URScript share (:mod:`olp.posts.rapid_flow`, :mod:`olp.posts.ur_flow` spell it).

A :class:`FlowWriter` turns the marker steps of :func:`olp.posts.flow.weave` and the flow
statements (:mod:`olp.ir_flow`) into lines of one language, keeping the block depth so that a
template can indent the ordinary instructions between them (:meth:`FlowWriter.pad`). A brand
subclasses it and states its spelling; everything that cannot be written exactly is a
:class:`FlowProblem`, which the post reports on the statement's line (:func:`flow_problems`)
before anything is rendered. The same code spells a statement for the check and for the text,
so the two cannot disagree.

Types. The IR's declarations carry the source language's type names; a KRL program's are mapped
to value kinds (:data:`KRL_KINDS`): ``BOOL`` bool, ``INT`` int, ``REAL`` real, ``CHAR[n]`` a
string of capacity n (KRL strings are CHAR arrays: the last dimension is the length), ``FRAME``
pose, ``POS``/``E6POS`` cartesian, ``AXIS``/``E6AXIS`` joints. Any other type (a structure, an
enumeration, ``SIGNAL``) is an error. :func:`Symbols.kind` infers the kind of an expression
where the program says it (constants, declared variables, operators); it is None where olp
cannot tell, and a language decides what it can write then (KRL's ``/`` of two INTs truncates,
so a division is written only where one side is known to be a real).

Names. KRL names are case-insensitive: a variable is written as its declaration spells it (or
as first written, when the program does not declare it), so a case-sensitive language sees one
variable.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

from olp import ir
from olp.diagnostics import Diagnostic
from olp.ir_flow import BLOCK_TYPES, FLOW_TYPES, bodies, leaves_and_blocks
from olp.ir_flow import walk_expression as walk
from olp.posts.sandbox import SafeText


class FlowProblem(ValueError):
    """A flow statement, or a part of it, that the language cannot write exactly."""


KRL_KINDS: Mapping[str, str] = {
    "BOOL": "bool",
    "INT": "int",
    "REAL": "real",
    "CHAR": "string",
    "FRAME": "pose",
    "POS": "cartesian",
    "E6POS": "cartesian",
    "AXIS": "joints",
    "E6AXIS": "joints",
}
"""KRL type name (upper case) -> value kind."""

MARKER_KINDS = (
    *("if", "elif", "else", "end_if", "switch", "case", "default", "end_switch", "while"),
    *("end_while", "repeat", "until", "loop", "end_loop", "for", "end_for", "routine_call"),
)
"""The kinds of :func:`olp.posts.flow.weave`'s marker steps."""
FLOW_STEP_KINDS = frozenset(
    (*MARKER_KINDS, "declare", "assign", "wait_until", "label", "goto", "exit", "return")
)
"""Every step kind a :class:`FlowWriter` writes (a template hands these to it)."""

COMPARISONS = frozenset({"==", "<>", "<", "<=", ">", ">="})
LOGICAL = frozenset({"and", "or", "xor"})
LOOP_TYPES = (ir.While, ir.Repeat, ir.Loop, ir.For)


@dataclass(frozen=True, slots=True)
class Variable:
    """A declared variable: its spelling, value ``kind``, array ``dims`` (the CHAR length is not
    one of them) and, for strings, the ``capacity`` (characters)."""

    name: str
    kind: str
    dims: tuple[ir.Expr | None, ...]
    capacity: int | None
    declare: ir.Declare


def variable_of(decl: ir.Declare) -> Variable:
    """The :class:`Variable` a declaration makes; a type olp does not map, and a variable of
    another module (``scope="external"``: no other vendor's program can refer to it), are a
    FlowProblem."""
    if decl.scope == "external":
        where = decl.span.file.replace("\\", "/").rsplit("/", 1)[-1]
        raise FlowProblem(
            f"{decl.name} is declared in another module's data list ({where}:{decl.span.line}), "
            "which only a program for the same controller can refer to: declare it in the "
            "program's own data to carry its value"
        )
    kind = KRL_KINDS.get(decl.type_name.upper())
    if kind is None:
        raise FlowProblem(f"the type {decl.type_name} has no counterpart olp writes")
    dims, capacity = decl.dims, None
    if kind == "string":
        if not dims:
            raise FlowProblem(f"{decl.name} is a single CHAR, which olp does not write")
        capacity = _positive_int(dims[-1], f"the length of {decl.name}")
        dims = dims[:-1]
    return Variable(decl.name, kind, dims, capacity, decl)


def _positive_int(expr: ir.Expr | None, what: str) -> int:
    if (
        isinstance(expr, ir.Constant)
        and isinstance(expr.value, int)
        and not isinstance(expr.value, bool)
        and expr.value > 0
    ):
        return expr.value
    raise FlowProblem(f"{what} must be a whole number above 0 written as a number")


def string_index(var: Variable, expr: ir.Index) -> tuple[ir.Expr, ...]:
    """The array indices of a string element (``names[2,]``: ``(2,)``; a plain string:
    ``()``); a character index (``text[3]``) is a FlowProblem: olp writes whole strings only."""
    head, tail = expr.indices[: len(var.dims)], expr.indices[len(var.dims) :]
    if len(head) < len(var.dims) or any(i is None for i in head) or len(tail) > 1:
        raise FlowProblem(f"olp writes whole strings only, not characters of {var.name}")
    if any(i is not None for i in tail):
        raise FlowProblem(f"olp writes whole strings only, not characters of {var.name}")
    return tuple(i for i in head if i is not None)


def constant_int(expr: ir.Expr | None) -> int | None:
    """The value of a whole-number constant (``3``, ``-3``), else None."""
    if isinstance(expr, ir.UnaryOp) and expr.op in ("-", "+"):
        inner = constant_int(expr.operand)
        return None if inner is None else (-inner if expr.op == "-" else inner)
    if isinstance(expr, ir.Constant) and type(expr.value) is int and not expr.enum:
        return expr.value
    return None


class Symbols:
    """The program's declared variables and the spelling of every name it uses."""

    def __init__(self, nodes: Iterable[Any]) -> None:
        self.variables: dict[str, Variable] = {}
        self.spelling: dict[str, str] = {}
        self.problems: dict[int, str] = {}
        every = list(leaves_and_blocks(nodes))
        for node in every:
            if isinstance(node, ir.Declare):
                self.spelling.setdefault(node.name.casefold(), node.name)
                try:
                    self.variables.setdefault(node.name.casefold(), variable_of(node))
                except FlowProblem as exc:
                    self.problems[id(node)] = str(exc)
        for node in every:
            for name in names_of(node):
                self.spelling.setdefault(name.casefold(), name)

    def name(self, name: str) -> str:
        """How ``name`` is written: as declared, or as first used."""
        return self.spelling.get(name.casefold(), name)

    def variable(self, name: str) -> Variable | None:
        return self.variables.get(name.casefold())

    def kind(self, expr: ir.Expr | None) -> str | None:
        """The value kind of ``expr`` where the program says it, else None."""
        if isinstance(expr, ir.Constant):
            return _constant_kind(expr)
        if isinstance(expr, ir.DigitalInput):
            return "bool"
        if isinstance(expr, ir.Name):
            var = self.variable(expr.name)
            return var.kind if var is not None and not var.dims else None
        if isinstance(expr, ir.Index) and isinstance(expr.base, ir.Name):
            var = self.variable(expr.base.name)
            return None if var is None else var.kind
        if isinstance(expr, ir.UnaryOp):
            return "bool" if expr.op == "not" else self.kind(expr.operand)
        if isinstance(expr, ir.BinaryOp):
            return self._binary_kind(expr)
        return None

    def _binary_kind(self, expr: ir.BinaryOp) -> str | None:
        if expr.op in COMPARISONS or expr.op in LOGICAL:
            return "bool"
        left, right = self.kind(expr.left), self.kind(expr.right)
        if expr.op in ("+", "-", "*", "/") and "real" in (left, right):
            return "real"
        if expr.op in ("+", "-", "*") and left == right == "int":
            return "int"
        return None


def _constant_kind(expr: ir.Constant) -> str | None:
    value = expr.value
    if expr.enum:
        return None
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, int):
        return "int"
    if isinstance(value, float):
        return "real"
    return "string"


def names_of(node: Any) -> Iterator[str]:
    """Every variable name ``node`` (a statement or block) reads or writes, not descending into
    the bodies of a block."""
    if isinstance(node, ir.For):
        yield node.variable
    for expr in exprs_of(node):
        for sub in walk(expr):
            if isinstance(sub, ir.Name):
                yield sub.name


def exprs_of(node: Any) -> list[Any]:
    """The expressions of one statement or block head (not of its bodies)."""
    fields = ("target", "condition", "value", "subject", "start", "stop", "step", "until")
    found = [getattr(node, f, None) for f in fields] + list(getattr(node, "dims", ()))
    found += [b.condition for b in getattr(node, "branches", ())]
    found += [v for c in getattr(node, "cases", ()) for v in c.values]
    if isinstance(node, ir.RoutineCall | ir.Expanded):
        found += list((node if isinstance(node, ir.RoutineCall) else node.call).args)
    return [e for e in found if e is not None]


def root_name(expr: Any) -> str | None:
    """The variable an assignment target writes (``a`` of ``a[1].x``)."""
    while isinstance(expr, ir.Index | ir.Member):
        expr = expr.base
    return expr.name if isinstance(expr, ir.Name) else None


def assigned_names(nodes: Iterable[Any]) -> set[str]:
    """Case-folded names the statements assign (in any nested body), FOR counters included."""
    out: set[str] = set()
    for node in leaves_and_blocks(nodes):
        name = root_name(node.target) if isinstance(node, ir.Assign) else None
        name = node.variable if isinstance(node, ir.For) else name
        if name is not None:
            out.add(name.casefold())
    return out


def direct_exit(loop: Any) -> bool:
    """Whether an :class:`~olp.ir.Exit` in ``loop``'s body leaves ``loop`` (not an inner loop)."""

    def search(nodes: Sequence[Any]) -> bool:
        for node in nodes:
            if isinstance(node, ir.Exit):
                return True
            inner = isinstance(node, BLOCK_TYPES) and not isinstance(node, LOOP_TYPES)
            if inner and any(search(body) for body in bodies(node)):
                return True
        return False

    return search(loop.body)


def for_problem(node: ir.For) -> str | None:
    """A FOR whose counter or end bound its body assigns: how often such a loop runs depends on
    when a language evaluates the bound, which olp does not model (olp's conservative choice)."""
    assigned = assigned_names(node.body)
    if node.variable.casefold() in assigned:
        return f"the FOR loop's body assigns its counter {node.variable}"
    for sub in walk(node.stop):
        if isinstance(sub, ir.Name) and sub.name.casefold() in assigned:
            return f"the FOR loop's body assigns {sub.name}, which its end value reads"
    return None


def jump_problems(program_nodes: Sequence[Any]) -> list[tuple[Any, str]]:
    """Jumps a language with block-scoped labels (RAPID) cannot make: a label defined twice, a
    GOTO to a missing label, and a GOTO into a block (into a loop, or into another branch of an
    IF or TEST than its own): the label's block must enclose the GOTO."""
    labels: dict[str, list[tuple[Any, tuple[Any, ...]]]] = {}
    gotos: list[tuple[Any, tuple[Any, ...]]] = []
    for node, path in _with_paths(program_nodes, ()):
        if isinstance(node, ir.Label):
            labels.setdefault(node.name.casefold(), []).append((node, path))
        elif isinstance(node, ir.Goto):
            gotos.append((node, path))
    out: list[tuple[Any, str]] = []
    for found in labels.values():
        if len(found) > 1:
            lines = ", ".join(str(n.span.line) for n, _ in found)
            out.append((found[1][0], f"the label {found[0][0].name} is defined twice ({lines})"))
    for goto, path in gotos:
        target = labels.get(goto.label.casefold())
        if target is None:
            out.append((goto, f"GOTO {goto.label}: the program has no such label"))
        elif path[: len(target[0][1])] != target[0][1]:
            out.append((goto, f"GOTO {goto.label} jumps into a block from outside it"))
    return out


def _with_paths(
    nodes: Sequence[Any], path: tuple[Any, ...]
) -> Iterator[tuple[Any, tuple[Any, ...]]]:
    for node in nodes:
        yield node, path
        if isinstance(node, BLOCK_TYPES):
            for k, body in enumerate(bodies(node)):
                yield from _with_paths(body, (*path, (id(node), k)))


@dataclass
class OpenBlock:
    """A block being written: its node, the kind of its marker, and what it needs at its end."""

    node: Any
    kind: str
    exit_label: str | None = None
    flag: str | None = None
    opened: bool = False


class FlowWriter:
    """Writes the flow steps of one file in one language; subclasses state the spelling.

    Call :meth:`lines` for every marker and flow statement in order, and :meth:`pad` for every
    other step (its indentation at the current depth). ``taken``: names in use, which generated
    helper names avoid (case-insensitively)."""

    LANGUAGE: ClassVar[str] = ""
    BASE_INDENT: ClassVar[int] = 0
    STEP: ClassVar[int] = 2
    NOT: ClassVar[str] = "NOT "
    """The logical negation, with the space after it."""

    def __init__(self, symbols: Symbols, taken: Iterable[str] = ()) -> None:
        self.symbols = symbols
        self.taken = {t.casefold() for t in taken} | set(symbols.spelling)
        self.stack: list[OpenBlock] = []
        self.helpers: list[tuple[str, str]] = []
        """Generated helper variables (name, kind) a file must declare."""

    # ---- expressions (the spelling of each language's subclass)

    def expr(self, expr: ir.Expr | None, nested: bool = False) -> str:
        """``expr`` in this language; a :class:`FlowProblem` where it cannot be said exactly."""
        raise NotImplementedError

    def unary(self, expr: ir.UnaryOp) -> str:
        """``not``, ``-`` and ``+``; bit operations have no counterpart olp writes."""
        operand = self.expr(expr.operand, nested=True)
        if expr.op == "not":
            return f"{self.NOT}{operand}"
        if expr.op == "-":
            return f"-{operand}"
        if expr.op == "+":
            return operand
        raise FlowProblem(f"bit operations have no {self.LANGUAGE} counterpart olp writes")

    # ---- the template's side

    def pad(self) -> int:
        """Spaces of an ordinary statement at the current depth, beyond the base indentation."""
        return self.STEP * len(self.stack)

    def lines(self, step: Any) -> SafeText:
        """The text of one marker or flow statement, indented."""
        method = getattr(self, "_" + step.kind)
        out: list[tuple[int, str]] = method(step.instruction)
        base = self.BASE_INDENT
        return SafeText("\n".join(" " * (base + self.STEP * d) + t for d, t in out))

    def helper(self, stem: str, kind: str) -> str:
        """A fresh helper variable name ``olp_<stem>_<n>`` no program name takes."""
        k = 1
        while f"olp_{stem}_{k}".casefold() in self.taken:
            k += 1
        name = f"olp_{stem}_{k}"
        self.taken.add(name.casefold())
        self.helpers.append((name, kind))
        return name

    @property
    def depth(self) -> int:
        return len(self.stack)

    def open_block(self, node: Any, kind: str, text: str) -> list[tuple[int, str]]:
        """The line that opens a block at the current depth; its body is one level deeper."""
        depth = self.depth
        self.stack.append(OpenBlock(node, kind))
        return [(depth, text)]

    def _innermost_loop(self) -> OpenBlock:
        for item in reversed(self.stack):
            if isinstance(item.node, LOOP_TYPES):
                return item
        raise FlowProblem(f"EXIT outside a loop cannot be written in {self.LANGUAGE}")

    # ---- the check's side

    def problem(self, node: Any) -> str | None:
        """Why ``node`` cannot be written, or None (tries every part of it)."""
        if id(node) in self.symbols.problems:
            return self.symbols.problems[id(node)]
        try:
            self.check_node(node)
        except FlowProblem as exc:
            return str(exc)
        return None

    def check_node(self, node: Any) -> None:
        """Spell every part of ``node``; raise FlowProblem for one that cannot be written."""
        raise NotImplementedError


def flow_problems(
    nodes: Sequence[Any],
    writer: FlowWriter,
    extra: Iterable[tuple[Any, str]] = (),
    unless_other: Iterable[tuple[Any, str]] = (),
) -> list[Diagnostic]:
    """One ``flow`` error per flow statement or block of ``nodes`` that ``writer`` cannot write,
    on its line, plus the ``extra`` (node, message) pairs a language adds, and each of the
    ``unless_other`` pairs whose statement ``writer`` finds nothing else wrong with (a name
    that is not a legal one is said once, not also as undeclared)."""
    found = []
    for node in leaves_and_blocks(nodes):
        if isinstance(node, FLOW_TYPES) and (problem := writer.problem(node)) is not None:
            found.append((node, problem))
    found += list(extra)
    found += [(node, message) for node, message in unless_other if writer.problem(node) is None]
    language = writer.LANGUAGE
    return [
        Diagnostic(
            "error",
            "flow",
            f"{node.kind.replace('_', ' ')} at line {node.span.line} cannot be written in "
            f"{language}: {problem}",
            node.span,
        )
        for node, problem in found
    ]


def flow_lines_filter(post: Any, step: Any) -> SafeText:
    """Template filter (``s | rapid_flow``, ``s | ur_flow``): the lines of a marker or flow
    statement, indented, by the post's writer of the file being rendered (``post.flow``)."""
    flow = getattr(post, "flow", None)
    assert isinstance(flow, FlowWriter), "a flow step outside a file with control flow"
    return flow.lines(step)


def flow_pad_filter(post: Any, step: Any) -> int:
    """Template filter (``s | rapid_pad``, ``s | ur_pad``): the extra indentation of an
    ordinary statement inside blocks (0 outside any, or in a file without control flow)."""
    flow = getattr(post, "flow", None)
    return 0 if flow is None else int(flow.pad())


def initial_value(var: Variable) -> ir.Expr | None:
    """The value a variable starts with: its declaration's, or for a single string of module
    data the text the data list sets as a whole (KRL ``sMsg[]="Ready"``); a FlowProblem where it
    is not made of constants (a declaration's value is written where no statement runs)."""
    decl = var.declare
    start = decl.value
    if var.kind == "string" and not var.dims:
        for indices, value in reversed(decl.elements):
            if all(i is None for i in indices):
                start = value
                break
    if start is not None and any(
        isinstance(e, ir.Name | ir.FunctionCall | ir.DigitalInput | ir.Index) for e in walk(start)
    ):
        raise FlowProblem(f"the initial value of {decl.name} is not made of constants")
    return start


def element_values(var: Variable, default: str, spell: Callable[[ir.Expr], str]) -> list[str]:
    """The initial values of a one-dimensional array ``var`` of module data, one text per
    element: ``default`` where the data list sets none, else the element's value (``spell``
    writes it). A FlowProblem where the size or an index is not a whole-number constant."""
    decl = var.declare
    size = constant_int(var.dims[0]) if len(var.dims) == 1 else None
    if size is None or size <= 0:
        raise FlowProblem(f"the size of the array {decl.name} must be a whole-number constant")
    out = [default] * size
    for indices, value in decl.elements:
        head, tail = indices[:1], indices[1:]  # a CHAR array's row: names[2,]="text"
        whole = all(t is None for t in tail) and (not tail or var.kind == "string")
        index = constant_int(head[0]) if head and whole else None
        if index is None or not 1 <= index <= size:
            raise FlowProblem(f"an element of {decl.name} set by the data list is not 1..{size}")
        out[index - 1] = spell(value)
    return out


def assigned_module_data(nodes: Sequence[Any]) -> list[tuple[ir.Declare, Any]]:
    """Each module-data declaration of ``nodes`` (``scope="module"``) that a statement assigns,
    with the first such statement: the variables whose value a run leaves for the next."""
    module = {
        n.name.casefold(): n
        for n in leaves_and_blocks(nodes)
        if isinstance(n, ir.Declare) and n.scope == "module"
    }
    found: dict[str, tuple[ir.Declare, Any]] = {}
    for node in leaves_and_blocks(nodes):
        target = node.target if isinstance(node, ir.Assign) else None
        if isinstance(node, ir.PathTrigger) and isinstance(node.action, ir.Assign):
            target = node.action.target
        root = root_name(target)
        names = [node.variable] if isinstance(node, ir.For) else [root] if root else []
        for name in names:
            decl = module.get(name.casefold())
            if decl is not None and name.casefold() not in found:
                found[name.casefold()] = (decl, node)
    return list(found.values())


UNDECLARED_HINT = (
    "declare it in the program (KRL: DECL in the .src, or in the module's .dat); a variable of "
    "$config.dat or of another module's data list is the KUKA controller's, which another "
    "vendor's program cannot refer to"
)
"""What would declare a name the program uses without a declaration."""
UNDECLARED_FUNCTION_HINT = (
    "olp writes only calls of the program's own functions (KRL: a DEFFCT of the module); a "
    "function of another module or of the KUKA controller is not one another vendor's "
    "program has"
)
"""What would declare a function the program calls without a declaration."""
EVENT_TYPES = (ir.InterruptDecl, ir.InterruptSwitch, ir.PathTrigger)
"""Statements a post other than KUKA's does not write (an ``unsupported`` error of their own)."""


def undeclared_names(
    nodes: Sequence[Any],
    routines: Sequence[ir.Routine],
    routines_see_main: bool,
    mapped: Callable[[str], bool] = lambda name: False,
) -> list[tuple[Any, str]]:
    """(statement, message) for each statement of the program (``nodes``, the analysis view:
    a call's expansion is checked as the routine's own body, once) or of one of ``routines``
    that uses a variable nothing declares: the written text would refer to a name the target
    language does not know (or, worse, to another module's variable of that name).

    Declared are: the program's declarations (any scope; one of another module's data is an
    error of its own, :func:`variable_of`), in a routine its parameters and its own
    declarations, and the program's module data and exported variables (the program's other
    variables too where ``routines_see_main``: URScript's first-level variables are global,
    RAPID's entry-routine data is not); FOR counters (RAPID declares its loop variable
    itself, URScript's while assigns it first); and what ``mapped`` says the post maps to a
    name of its own. A function a call in an expression names must be one of ``routines``
    (or one ``mapped``): the text would otherwise call a function the target language does not
    have (KRL's ``fnGetPart(1)`` of another module). Interrupt and trigger statements are not
    looked into: a post that does not write them refuses them."""
    main = [n for n in _own_nodes(nodes) if isinstance(n, ir.Declare)]
    shared = {d.name.casefold() for d in main if d.scope in ("module", "external") or d.exported}
    functions = {r.name.casefold() for r in routines}
    declared = {d.name.casefold() for d in main}
    out = _undeclared_in(nodes, _Declared(declared, functions, mapped), "the program")
    for routine in routines:
        own = {p.name.casefold() for p in routine.params}
        own |= {d.name.casefold() for d in routine.declarations}
        own |= {n.name.casefold() for n in _own_nodes(routine.body) if isinstance(n, ir.Declare)}
        seen = own | shared | (declared if routines_see_main else set())
        known = _Declared(seen, functions, mapped)
        out += _undeclared_in(routine.body, known, f"routine {routine.name}")
    return out


@dataclass(frozen=True, slots=True)
class _Declared:
    """The variables (case-folded) and functions a part of the program may name."""

    variables: set[str]
    functions: set[str]
    mapped: Callable[[str], bool]

    def problem(self, node: Any, where: str, counters: set[str]) -> str | None:
        for name in names_of(node):
            key = name.casefold()
            if key not in self.variables and key not in counters and not self.mapped(name):
                return f"{name} is not declared in {where}: {UNDECLARED_HINT}"
        for name in calls_of(node):
            if name.casefold() not in self.functions and not self.mapped(name):
                return f"{name}(...) is not a function of the program: {UNDECLARED_FUNCTION_HINT}"
        return None


def calls_of(node: Any) -> Iterator[str]:
    """The function every call in ``node``'s own expressions names (not in its bodies)."""
    for expr in exprs_of(node):
        for sub in walk(expr):
            if isinstance(sub, ir.FunctionCall):
                yield sub.name


def _own_nodes(nodes: Iterable[Any]) -> Iterator[Any]:
    """Every node of ``nodes``, blocks included, but not the bodies of call expansions."""
    for node in nodes:
        yield node
        if isinstance(node, BLOCK_TYPES) and not isinstance(node, ir.Expanded):
            for body in bodies(node):
                yield from _own_nodes(body)


def _undeclared_in(nodes: Sequence[Any], known: _Declared, where: str) -> list[tuple[Any, str]]:
    own = list(_own_nodes(nodes))
    counters = {n.variable.casefold() for n in own if isinstance(n, ir.For)}
    out: list[tuple[Any, str]] = []
    for node in own:
        if isinstance(node, EVENT_TYPES):
            continue
        problem = known.problem(node, where, counters)
        if problem is not None:
            out.append((node, problem))
    return out


def uncalled_bodies(nodes: Sequence[Any], routines: Sequence[ir.Routine]) -> list[Any]:
    """The bodies' nodes of the ``routines`` no call in ``nodes`` (the analysis view) expands
    (a function, an interrupt handler): written all the same, so checked all the same."""
    expanded = (n for n in leaves_and_blocks(nodes) if isinstance(n, ir.Expanded))
    called = {n.call.name.casefold() for n in expanded}
    return [n for r in routines if r.name.casefold() not in called for n in r.body]
