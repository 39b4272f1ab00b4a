"""The base of every post: the shared checks, the escaping of user text, number checks, shared
filters and IR rewrites; a brand (:mod:`olp.posts.kuka`, ...) states only what differs.

In the spirit of sqlglot's dialect generators, a post is a class whose tables say what its
language is like, spread from the base::

    class KukaPost(Post):
        VENDOR = "kuka"
        NAME_RULE = NameRule(max_length=24, reserved=KEYWORDS)
        IO_RANGE = (1, 4096)
        NUMBERS = {**Post.NUMBERS, "vel_cp": NumberFormat(...)}
        FILTERS = {**Post.FILTERS, "krl_frame": lambda post, pose: ...}

and its templates (``posts/<name>/``) say how a program is spelled. A build runs
:meth:`Post.prepare` (the ``TRANSFORMS``: IR rewrites the language needs, such as capping blend
radii), :meth:`Post.check` (what cannot be written, as located diagnostics), then
:meth:`Post.render`.

What every post checks (:meth:`Post.check`), so that no brand can forget it:

* an instruction kind the post cannot write (``KINDS``) is an error on its line, never a silent
  drop (kind ``unsupported``);
* comments (``COMMENTS``): a line break becomes another comment line; another control character,
  or a character the output encoding lacks, is an error (``comment``);
* calls: the routine's name must already be legal (``NAME_RULE``; olp never renames what another
  program defines), each argument must be a literal or a name the language allows
  (``CALL_ARGUMENTS``): ``Grip(1;MoveAbsJ ...)`` can never write a live move (``call_name``,
  ``call_argument``);
* digital I/O numbers within the controller's range (``IO_RANGE``, ``io_range``);
* a station robot of another brand than the post's (a warning, ``foreign_robot``);
* a motion to a run-time target (:class:`~olp.ir.RuntimeMove`) is written only by a post whose
  ``KINDS`` hold ``runtime_move``, from a template folder that declares ``runtime_targets:
  true``; else an error on its line (``runtime_target``);
* a :class:`~olp.ir.Verbatim` statement of another language than the post's ``VERBATIM`` is an
  error naming its line (``verbatim``); with the post option ``foreign_verbatim: drop`` (in a
  template folder, or ``olp build --drop-foreign-verbatim``) it is left out with a warning
  showing its text (``verbatim_dropped``).

Numbers are written through :meth:`Post.number` with a quantity of ``NUMBERS``
(:mod:`olp.posts.numbers`): a value the controller cannot hold as checked and timed is an error on
the instruction being written.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from olp.diagnostics import Diagnostic
from olp.errors import PostError
from olp.ir import GENERATED, ArcOrientation, Program, SourceSpan
from olp.posts.numbers import NumberError, NumberFormat, format_number, format_numbers
from olp.posts.sandbox import PostSandbox, make_environment
from olp.posts.text import (
    ArgumentRule,
    CommentRule,
    NameRule,
    basename,
    encodable,
    plain,
    show_character,
)

if TYPE_CHECKING:
    from olp.compiled import CompiledProgram, PathBlock, Step
    from olp.posts.manifest import PostManifest
    from olp.posts.rows import PostRows
    from olp.posts.stream_transforms import WindowTransform
    from olp.posts.view import PostStep, RowColumns

FloatArray = NDArray[np.float64]

Filter = Callable[..., Any]
"""A template filter: ``(post, value, *args) -> value``; the post is bound when the sandbox is
made, so filters can reach the post's rules, options and number formats."""

Transform = Callable[["CompiledProgram", "Post"], "tuple[CompiledProgram, list[Diagnostic]]"]
"""An IR rewrite a language needs before rendering, with the diagnostics it gives."""

ALL_KINDS = frozenset(
    {
        "joint",
        "linear",
        "circular",
        "wait",
        "set_output",
        "wait_input",
        "call",
        "comment",
        "verbatim",
    }
    | {"declare", "assign", "wait_until", "label", "goto", "exit", "return"}
)
"""Instruction kinds of the IR (a program's blocks are not instructions: see ``WRITES_FLOW``)."""

GENERIC_NUMBER = NumberFormat("number", "", 3)
"""The ``num`` filter's format where a template names no quantity (range: any finite value)."""


def _num(post: Post, value: float, decimals: int = 3) -> str:
    fmt = NumberFormat("number", "", int(decimals))
    return post.number_with(fmt, value)


def _number(post: Post, value: float, quantity: str) -> str:
    return post.number(quantity, value)


def _deg(post: Post, value: float) -> float:
    return math.degrees(value)


def _basename(post: Post, path: str) -> str:
    """The last component of a path written with ``/`` or ``\\``, escaped for a comment."""
    return post.plain_text(basename(path))


class Post:
    """A post-processor: rules, checks and filters of one controller language, rendering the
    templates of one folder (``manifest``). A Post renders one program at a time."""

    NAME: ClassVar[str] = ""
    """The registry name (``olp build --post NAME``)."""
    FOLDER: ClassVar[Path | None] = None
    """The template folder of a registered post (None: the bundled ``posts/<NAME>/``)."""
    VENDOR: ClassVar[str] = ""
    """The robot brand whose controllers run this code ("" for a brand-neutral post)."""
    LANGUAGE: ClassVar[str] = "robot code"
    """The language, for messages."""
    NAME_RULE: ClassVar[NameRule] = NameRule()
    COMMENTS: ClassVar[CommentRule] = CommentRule()
    CALL_ARGUMENTS: ClassVar[ArgumentRule] = ArgumentRule()
    IO_RANGE: ClassVar[tuple[int, int] | None] = None
    """Digital output and input numbers the controller has (None: no numbers are written)."""
    KINDS: ClassVar[frozenset[str]] = ALL_KINDS
    """Instruction kinds the templates write."""
    WRITES_FLOW: ClassVar[bool] = False
    WRITES_ROUTINES: ClassVar[bool] = False
    """Whether the post writes the program's routines (:attr:`olp.ir.Program.routines`) as
    routines of its language, and calls as calls (with ``routines: true`` in its manifest);
    otherwise each routine's body is written out at every call (:meth:`writes_routines`)."""
    """Whether the templates write control flow and data statements (:mod:`olp.ir_flow`); a
    post that does not stops on a program holding them, naming the first one, rather than
    writing its instructions in a row. So does a template folder whose ``post.yaml`` does not
    say ``flow: true`` (a copy made before olp wrote control flow would write each block's body
    unconditionally)."""
    PROGRAM_PARAMS: ClassVar[str | None] = None
    """Why this language's program cannot take the program's own parameters
    (:attr:`olp.ir.Program.params`), for the located error on a program that has them; None:
    the post writes them (with ``program_params: true`` in its manifest; a folder copied before
    olp wrote them is refused the same way)."""
    PROGRAM_RETURNS: ClassVar[str | None] = None
    """Why this language's program cannot give a result (:attr:`olp.ir.Program.returns`: a
    function program, which other programs call in an expression), for the located error on
    a program that gives one; None: the post writes it (with ``program_returns: true`` in its
    manifest; a folder copied before olp wrote it is refused the same way)."""
    VERBATIM: ClassVar[str | None] = None
    """The language of :class:`~olp.ir.Verbatim` statements this post writes unchanged (KUKA:
    ``"krl"``); a verbatim statement of another language is an error on its line."""
    NUMBERS: ClassVar[Mapping[str, NumberFormat]] = {"number": GENERIC_NUMBER}
    FILTERS: ClassVar[Mapping[str, Filter]] = {
        "num": _num,
        "number": _number,
        "deg": _deg,
        "basename": _basename,
    }
    TRANSFORMS: ClassVar[tuple[Transform, ...]] = ()
    NULL_TOOL_NAME: ClassVar[str | None] = None
    """The controller's own name for no tool (written instead of a generated name)."""
    NULL_FRAME_NAME: ClassVar[str | None] = None
    """The controller's own name for its reference frame."""
    PREDEFINED_NAMES: ClassVar[frozenset[str]] = frozenset()
    """Names the controller defines: generated data never take them."""
    ARC_ORIENTATIONS: ClassVar[frozenset[ArcOrientation]] = frozenset({ArcOrientation.INTERPOLATE})
    """The orientation rules of circular moves this language can write (the three-point arc
    interpolating start to end, unless a brand says otherwise); any other is an error on the
    move's line, never a different path."""
    RUNTIME_REFUSAL: ClassVar[str] = ""
    """Why the post cannot write motions to run-time targets (``runtime_move`` not in
    :attr:`KINDS`), for the error on such a motion."""
    RUNTIME_RELATIVE: ClassVar[frozenset[str]] = frozenset()
    """The :attr:`olp.ir.RuntimeMove.relative` forms this language writes (a target that
    refers to a start position known only at run time); any other is an error on its line."""
    ARC_ANGLE: ClassVar[bool] = False
    """Whether a circular move's circular angle (KUKA's CA) can be written."""
    ACCELERATIONS: ClassVar[frozenset[str]] = frozenset()
    """The path-move acceleration limits of :class:`olp.ir.Speed` this language can write
    (``"linear_acceleration"``, ``"angular_acceleration"``); one it cannot is a warning on the
    first move that sets it (the robot then runs with the controller's own value, and the
    cycle time differs from the estimate)."""
    ROWS: ClassVar[bool] = False
    """Whether the post writes runs of linear moves with a row writer (:mod:`olp.posts.rows`);
    used only where the template folder says ``rows: true`` and :meth:`rows_enabled` agrees."""

    COLUMNS: ClassVar[bool] = False
    """Whether the row writer also takes a toolpath's rows as columns
    (:class:`~olp.posts.view.RowColumns`): a toolpath is then written without a step per row
    (:meth:`columns_enabled`)."""
    STREAMS: ClassVar[bool] = False
    """Whether a big toolpath may be written window by window (:mod:`olp.posts.stream`): the
    templates write each rows item only through row writer filters applied to the item itself,
    nothing between two rows items, and nothing else in a file is computed from its rows but
    what :meth:`context_rows` keeps for :meth:`context_values`."""
    WINDOW_TRANSFORMS: ClassVar[tuple[type[WindowTransform], ...] | None] = None
    """The ``TRANSFORMS`` as a streamed build applies them, window by window, to a program
    without control flow (:mod:`olp.posts.stream_transforms`); None where they cannot be (a
    post with ``TRANSFORMS`` then builds whole)."""
    ONCE_PER_PROGRAM: ClassVar[frozenset[str]] = frozenset()
    """Diagnostic kinds :meth:`check_program` gives at most once per message in a program
    (ABB's ``tool_load``: once per tool): a streamed build, checked window by window, keeps
    the first."""
    TOTAL_KINDS: ClassVar[frozenset[str]] = frozenset()
    """Diagnostic kinds :meth:`check_program` gives from the whole program's totals (UR's
    ``program_too_long``): a streamed build drops them from its windows' checks and asks
    :meth:`check_totals` once at the end."""
    STREAM_PARTS: ClassVar[bool] = False
    """Whether a streamed build renders each part's templates whole, from the part's rows
    kept in memory (bounded by the manifest's ``limits``; the number of parts is counted
    first), rather than splicing the row writers' text into the file: for templates that
    compute a file's text from all its rows (Fanuc's line numbers, ``LINE_COUNT``)."""
    STREAM_NEUTRAL_FILTERS: ClassVar[frozenset[str]] = frozenset()
    """Filters a template may apply to a rows item that read nothing of its rows (ABB's and
    UR's indentation inside blocks): a streamed build runs them on the rows' stand-in instead
    of taking them for a row writer."""

    def __init__(self, manifest: PostManifest) -> None:
        self.manifest = manifest
        self.current_step: PostStep | PostRows | RowColumns | None = None
        self.problems: list[Diagnostic] = []
        self.collecting = False
        """While rendering: numbers that cannot be written are collected as diagnostics on the
        instruction being written (else :class:`~olp.posts.numbers.NumberError` is raised)."""

    @property
    def options(self) -> Mapping[str, Any]:
        return self.manifest.options

    @property
    def name(self) -> str:
        return self.manifest.name

    # ----------------------------------------------------------------------------------------
    # Hooks a brand overrides

    def step_values(self, robot: Any, joints: FloatArray) -> list[Mapping[str, Any]]:
        """Per motion, from its planned joints ``(N, dof)`` rad: values the templates need
        (KUKA Status/Turn, ABB confdata), as ``PostStep.vendor``."""
        return [{} for _ in range(joints.shape[0])]

    def step_columns(self, robot: Any, joints: FloatArray) -> Mapping[str, Any]:
        """:meth:`step_values` of a toolpath's rows ``(N, dof)`` rad as columns: ``{key:
        array (N,)}`` (a brand with a column writer computes them as arrays)."""
        values = self.step_values(robot, joints)
        keys = values[0].keys() if values else ()
        return {key: np.array([v[key] for v in values]) for key in keys}

    def context_values(self, steps: Sequence[PostStep]) -> Mapping[str, Any]:
        """Per file: the ``vendor`` context entry (e.g. ABB's custom speed data)."""
        return {}

    def context_rows(self, rows: RowColumns) -> Sequence[int]:
        """The rows (positions in ``rows``, ascending) of a toolpath's rows whose values
        :meth:`context_values` needs: a streamed build (:mod:`olp.posts.stream`) keeps only
        these of a file's rows for it, and gets the same ``vendor`` entry as from all of them.
        None by default (:meth:`context_values` reads no row)."""
        return ()

    def check_instruction(self, step: Step, compiled: CompiledProgram) -> list[Diagnostic]:
        """What this language cannot say exactly about one instruction."""
        return []

    def check_program(self, compiled: CompiledProgram) -> list[Diagnostic]:
        """What this language cannot say exactly about the whole program."""
        return []

    def check_totals(self, motions: int) -> list[Diagnostic]:
        """The :attr:`TOTAL_KINDS` diagnostics of a program of ``motions`` written motions
        (none by default)."""
        return []

    def reserved_names(self, compiled: CompiledProgram) -> Sequence[str]:
        """Names the program's own statements use (variables, labels), which the names olp
        makes up for points, tools and frames must not take; none by default."""
        return ()

    # ----------------------------------------------------------------------------------------
    # The pipeline

    def writes_routines(self) -> bool:
        """Whether this post, with its template folder, writes routines as routines."""
        return self.WRITES_ROUTINES and self.manifest.routines

    def writes_program_params(self) -> bool:
        """Whether this post, with its template folder, writes the program's parameters."""
        return self.PROGRAM_PARAMS is None and self.manifest.program_params

    def writes_program_returns(self) -> bool:
        """Whether this post, with its template folder, writes a function program."""
        return self.PROGRAM_RETURNS is None and self.manifest.program_returns

    def _returns_error(self, program: Program) -> Diagnostic:
        from olp.ir_flow import leaves

        why = self.PROGRAM_RETURNS or (
            f"the template folder {self.manifest.folder} does not say program_returns: true (a "
            "copy made before olp wrote them would write the program as one without a result)"
        )
        message = (
            f"program {program.name} is a function giving a {program.returns}, which the "
            f"{self.LANGUAGE} post does not write: {why}"
        )
        hint = (
            "write it as a program without a result for this controller, or build it for KRL"
            if self.PROGRAM_RETURNS
            else "update the folder from olp's bundled post and add program_returns: true"
        )
        spans = [n.span for n in leaves(program.instructions) if n.kind == "return"]
        spans += [p.span for p in program.params]
        return Diagnostic(
            "error", "program_returns", message, spans[0] if spans else None, hint=hint
        )

    def _params_error(self, program: Program) -> Diagnostic:
        names = ", ".join(p.name for p in program.params)
        why = self.PROGRAM_PARAMS or (
            f"the template folder {self.manifest.folder} does not say program_params: true (a "
            "copy made before olp wrote them would write the program without them)"
        )
        message = (
            f"program {program.name} takes parameters ({names}), which the {self.LANGUAGE} post "
            f"does not write: {why}"
        )
        hint = (
            "write it as a program without parameters for this controller (give them values "
            "in its body), or build it for KRL"
            if self.PROGRAM_PARAMS
            else "update the folder from olp's bundled post and add program_params: true"
        )
        return Diagnostic("error", "program_params", message, program.params[0].span, hint=hint)

    def prepare(self, compiled: CompiledProgram) -> tuple[CompiledProgram, list[Diagnostic]]:
        """Write routines out at their calls where the post does not write routines
        (:func:`olp.posts.routines.written_out`), then apply the ``TRANSFORMS`` in order."""
        from olp.posts.routines import written_out

        found: list[Diagnostic] = []
        if compiled.program.routines and not self.writes_routines():
            compiled, found = written_out(compiled, self)
        for transform in self.TRANSFORMS:
            compiled, more = transform(compiled, self)
            found += more
        return compiled, found

    def check(self, compiled: CompiledProgram) -> list[Diagnostic]:
        """Everything this post reports about ``compiled``; errors mean nothing is written."""
        out = self._foreign_robot(compiled)
        if compiled.program.params and not self.writes_program_params():
            out.append(self._params_error(compiled.program))
        if compiled.program.returns is not None and not self.writes_program_returns():
            out.append(self._returns_error(compiled.program))
        if compiled.program.has_flow and not (self.WRITES_FLOW and self.manifest.flow):
            return [*out, self._flow_error(compiled)]
        from olp.compiled import PathBlock, items_of

        compiled = self.render_form(compiled)
        for item in items_of(compiled.steps):
            if isinstance(item, PathBlock):
                out += self.check_block(item, compiled)
                continue
            out += self._shared_checks(item)
            out += self.check_instruction(item, compiled)
        out += self._acceleration_checks(compiled.steps)
        if compiled.program.routines and self.writes_routines():
            from olp.posts.routines import once_per_statement, routine_checks

            out += routine_checks(compiled, self)
            return once_per_statement([*out, *self.check_program(compiled)])
        return out + self.check_program(compiled)

    def check_block(self, block: PathBlock, compiled: CompiledProgram) -> list[Diagnostic]:
        """:meth:`check` of a toolpath's rows (linear moves to Cartesian targets, one tool
        and frame): what the shared checks say of a linear move, and :meth:`check_rows`."""
        if "linear" not in self.KINDS:
            return [f for step in block.steps() for f in self._shared_checks(step)]
        return self.check_rows(block, compiled)

    def check_rows(self, block: PathBlock, compiled: CompiledProgram) -> list[Diagnostic]:
        """:meth:`check_instruction` of a toolpath's rows; row by row unless a brand says
        what it checks of them as arrays."""
        return [f for step in block.steps() for f in self.check_instruction(step, compiled)]

    def columns_enabled(self, compiled: CompiledProgram) -> bool:
        """Whether a toolpath's rows go to the column writer without a step per row: the
        post has one (:attr:`COLUMNS`), rows are enabled, and the program has no control flow
        (which is woven into the steps one by one)."""
        return self.COLUMNS and self.rows_enabled() and not compiled.program.has_flow

    def render_form(self, compiled: CompiledProgram) -> CompiledProgram:
        """``compiled`` as :meth:`render` walks it: toolpath blocks kept as arrays where
        :meth:`columns_enabled`, else made into steps once (the templates walk them several
        times)."""
        return compiled if self.columns_enabled(compiled) else compiled.flat()

    def _acceleration_checks(self, steps: Sequence[Step]) -> list[Diagnostic]:
        """One warning per acceleration limit the program sets on path moves and this
        language cannot write (:attr:`ACCELERATIONS`), on the first such move's line."""
        out = []
        for name in ("linear_acceleration", "angular_acceleration"):
            if name in self.ACCELERATIONS and self.manifest.accelerations:
                continue
            count, first = _setting(steps, name)
            if first is not None:
                what = _ACCELERATION_NAMES[name]
                msg = (
                    f"the {self.LANGUAGE} post cannot write the {what} set on "
                    f"{count} path move(s): the controller's own applies, and the cycle "
                    "time differs from the estimate"
                )
                if name in self.ACCELERATIONS:
                    msg += (
                        f" (the template folder {self.manifest.folder.name} does not declare "
                        "accelerations: true; a copy of an older post: copy the bundled "
                        "templates' acceleration lines and declare it)"
                    )
                out.append(_warning("acceleration", msg, first))
        return out

    def render(
        self, compiled: CompiledProgram, name: str | None = None, *, prepared: bool = False
    ) -> dict[str, str]:
        """Every file of the program (:func:`olp.posts.render.render`), after the
        ``TRANSFORMS`` (which are idempotent: a program :meth:`prepare` already rewrote stays as
        it is), so the text never depends on whether the caller prepared the program.
        ``prepared``: the caller has just applied :meth:`prepare` (skip doing it again)."""
        from olp.posts.render import render

        if not prepared:
            compiled = self.prepare(compiled)[0]
        return render(self.render_form(compiled), self, name)

    def write(self, files: Mapping[str, str], folder: Path) -> list[Path]:
        """Encode every file in the manifest's encoding (a character it lacks is a PostError
        naming the file, line and column: :meth:`check` should have reported it on its source
        line already), then write them as one set into ``folder``
        (:func:`olp.output.write_folder`: all or nothing, stale parts of an earlier build
        removed)."""
        from olp.output import write_folder

        encoding = self.manifest.encoding
        encoded = {}
        for fname, text in files.items():
            try:
                encoded[fname] = text.encode(encoding)
            except UnicodeEncodeError as exc:
                bad = text[exc.start : exc.end]
                line = text.count("\n", 0, exc.start) + 1
                column = exc.start - (text.rfind("\n", 0, exc.start) + 1) + 1
                raise PostError(
                    f"{fname}:{line}:{column}: character {bad!r} cannot be written in {encoding}"
                ) from exc
        return write_folder(encoded, folder)

    def environment(self) -> PostSandbox:
        """The sandboxed Jinja environment of this post's folder, with its filters bound."""
        filters = {name: _bind(fn, self) for name, fn in self.FILTERS.items()}
        return make_environment(self.manifest.folder, filters)

    # ----------------------------------------------------------------------------------------
    # Numbers and text

    def number(self, quantity: str, value: float) -> str:
        """``value`` in the printed unit of ``quantity`` (``NUMBERS``), checked; a value that
        cannot be written becomes an error on the instruction being written."""
        return self.number_with(self.NUMBERS[quantity], value)

    def number_column(self, quantity: str, values: Any, steps: Sequence[PostStep]) -> list[str]:
        """:meth:`number` for values (n, k) or (n,), row r belonging to ``steps[r]``: spelled and
        checked as one column (:func:`~olp.posts.numbers.format_numbers`); a value that cannot
        be written is an error on its own row's instruction. Row-major, n * k texts."""
        v = np.asarray(values, dtype=np.float64)
        fmt = self.NUMBERS[quantity]
        try:
            return format_numbers(v, fmt)
        except NumberError:
            pass
        saved, out = self.current_step, []
        per_row = v.reshape(len(steps), -1)
        for step, row in zip(steps, per_row, strict=True):
            self.current_step = step
            out += [self.number_with(fmt, float(x)) for x in row]
        self.current_step = saved
        return out

    def number_texts(
        self, quantity: str, values: Any, at: Callable[[int], PostStep]
    ) -> NDArray[np.str_]:
        """:meth:`number` of values (n, k) or (n,) as an array of texts of the same shape,
        spelled and checked as columns (:func:`olp.posts.rows.number_column`); row r is
        ``at(r)``'s: a value that cannot be written is an error on that row's instruction."""
        from olp.posts.rows import number_column

        v = np.asarray(values, dtype=np.float64)
        fmt = self.NUMBERS[quantity]
        texts, ok = number_column(v, fmt)
        if ok:
            return texts.reshape(v.shape)
        saved, out = self.current_step, []
        per_row = v.reshape(v.shape[0], -1) if v.ndim else v.reshape(1, 1)
        for r, row in enumerate(per_row):
            self.current_step = at(r)
            out += [self.number_with(fmt, float(x)) for x in row]
        self.current_step = saved
        return np.array(out, dtype=np.str_).reshape(v.shape)

    def rows_enabled(self) -> bool:
        """Whether runs of linear moves go to the row writer: the post has one, the template
        folder declares ``rows: true``, and (per brand) the options allow it."""
        return self.ROWS and self.manifest.rows

    def group(
        self, steps: Sequence[PostStep | RowColumns]
    ) -> list[PostStep | PostRows | RowColumns]:
        """A file's steps as its templates see them (:func:`olp.posts.rows.group_rows` where
        :meth:`rows_enabled`)."""
        from olp.posts.rows import group_rows

        return group_rows(steps) if self.rows_enabled() else list(steps)

    def numbers(self, quantity: str, values: Any) -> list[str]:
        """:meth:`number` for an array of values (N,)."""
        try:
            return format_numbers(values, self.NUMBERS[quantity])
        except NumberError as exc:
            self._refuse(str(exc))
            return ["?"] * int(np.size(values))

    def number_with(self, fmt: NumberFormat, value: float) -> str:
        try:
            return format_number(value, fmt)
        except NumberError as exc:
            self._refuse(str(exc))
            return "?"

    def _refuse(self, message: str) -> None:
        if not self.collecting:
            raise NumberError(message)
        step = self.current_step
        span = step.instruction.span if step is not None else None
        index = step.index if step is not None else None
        self.problems.append(Diagnostic("error", "number", message, span, index))

    def comment_lines(self, text: str) -> tuple[str, ...]:
        """A comment's lines as this language writes them (checked by :meth:`check`)."""
        return tuple(self.COMMENTS.lines(text))

    def comment_node_lines(self, comment: Any) -> tuple[str, ...]:
        """The lines an :class:`~olp.ir.Comment` is written as, each through the language's
        comment rule (:meth:`comment_lines`).

        A KUKA pendant fold (``fold``) is written as its :attr:`~olp.ir.Comment.title` alone
        when it opens, and not at all when it closes: the languages other than KRL have no
        folds, and what follows a fold header's title (``;%{PE}%R 8.3.31,%MKUKATPBASIS,...``)
        is the pendant's record of its inline form, noise to a reader of RAPID, URScript or
        LS; the title (``PTP P1 CONT Vel=100 % PDAT1``) still says what the lines below do. A
        comment read from a source program (``from_source``) has the characters the output's
        encoding lacks written as ``?`` (:meth:`check` warns where it does).
        """
        if comment.fold == "close" or (comment.fold == "open" and not comment.title):
            return ()
        lines = self.comment_lines(comment.title)
        return self._source_lines(lines) if comment.from_source else lines

    def _source_lines(self, lines: tuple[str, ...]) -> tuple[str, ...]:
        """A source comment's ``lines`` with the characters the encoding lacks as ``?``."""
        encoding = self.manifest.encoding
        if all(encodable(line, encoding) is None for line in lines):
            return lines
        return tuple(plain(line, encoding) for line in lines)

    def plain_text(self, text: str) -> str:
        """Informational text (a file name in a header comment): control characters and
        characters the output encoding lacks become ``?``."""
        return plain(text, self.manifest.encoding)

    # ----------------------------------------------------------------------------------------
    # Shared checks

    def renamed(self, program: Program, name: str | None = None) -> list[Diagnostic]:
        """A warning where the program's file and routine get another name than asked for
        (``name``, else the program's own): one the language does not allow (KRL: longer than
        24 characters, :attr:`NAME_RULE`) is made legal, and other programs that call it by the
        old name would no longer find it."""
        wanted = name or program.name
        if self.NAME_RULE.is_legal(wanted):
            return []
        legal = self.NAME_RULE.legal(wanted)
        message = (
            f"the program is written as {legal}: {_quote(wanted)} is not a legal "
            f"{self.LANGUAGE} name ({self.NAME_RULE.describe()}); a program that calls it by "
            "that name must call it by the new one"
        )
        span = SourceSpan(program.source, 1, 1) if program.source != "<memory>" else GENERATED
        return [Diagnostic("warning", "renamed", message, span)]

    def _foreign_robot(self, compiled: CompiledProgram) -> list[Diagnostic]:
        robot = compiled.station.robot
        if not self.VENDOR or robot.vendor == self.VENDOR:
            return []
        return [
            Diagnostic(
                "warning",
                "foreign_robot",
                f"the station's robot is a {robot.name} ({robot.vendor}): the {self.LANGUAGE} "
                "written holds that robot's joints and poses",
                hint=f"to run it, compile on a station with a {self.VENDOR} robot",
            )
        ]

    def _shared_checks(self, step: Step) -> list[Diagnostic]:
        ins: Any = step.instruction
        kind = ins.kind
        if kind == "verbatim":
            return self._verbatim_checks(step, ins)
        if kind == "runtime_move":
            return self._runtime_checks(step, ins)
        if kind not in self.KINDS:
            what = kind.replace("_", " ")
            article = "an" if what[:1] in "aeiou" else "a"
            msg = f"the {self.LANGUAGE} post cannot write {article} {what} instruction"
            return [_error("unsupported", msg, step)]
        if kind == "comment":
            return self._comment_checks(step, ins)
        if kind == "call":
            return self._call_checks(step, ins.name, ins.args)
        if kind in ("set_output", "wait_input"):
            return self._io_checks(step, kind, ins.index)
        if kind == "circular":
            return self._arc_checks(step, ins)
        return []

    def _runtime_checks(self, step: Step, ins: Any) -> list[Diagnostic]:
        """A motion to a run-time target: written by a post that can (``"runtime_move"`` in
        :attr:`KINDS`) from a template folder that says so (``runtime_targets: true``: a copy
        made before olp wrote them would leave the motion out); a circular one as any arc.
        What the language can name as a target is the brand's :meth:`check_instruction`."""
        what = (
            f"a {ins.motion} move with the controller's settings (line {ins.span.line})"
            if ins.controller_settings
            else f"a {ins.motion} move to a target known only at run time (line {ins.span.line})"
        )
        if "runtime_move" not in self.KINDS:
            why = f": {self.RUNTIME_REFUSAL}" if self.RUNTIME_REFUSAL else ""
            msg = f"the {self.LANGUAGE} post cannot write {what}{why}"
            return [_error("runtime_target", msg, step)]
        if not self.manifest.runtime_targets:
            msg = (
                f"the {self.LANGUAGE} post's template folder {self.manifest.folder.name} does not "
                f"declare that it writes {what} (runtime_targets: true in its post.yaml)"
            )
            hint = (
                f"use the bundled {self.NAME} post, or copy its templates' run-time motion lines "
                "and declare runtime_targets: true"
            )
            return [_error("runtime_target", msg, step, hint=hint)]
        if ins.controller_settings and self.VERBATIM is None:
            why = f" ({ins.reason})" if ins.reason else ""
            msg = (
                f"the {self.LANGUAGE} post cannot write {what}: it runs with the settings the "
                f"source's controller holds there{why}, which only a program in that language "
                "keeps"
            )
            hint = (
                "set the tool, base and speeds in the source before this motion (an inline form "
                "does); for a call of a routine that leaves them and the robot as they were, "
                "name it with --call-keeps-settings"
            )
            return [_error("runtime_target", msg, step, hint=hint)]
        if ins.relative is not None and ins.relative not in self.RUNTIME_RELATIVE:
            return [_error("runtime_target", _relative_refusal(self.LANGUAGE, what, ins), step)]
        return self._arc_checks(step, ins) if ins.motion == "circular" else []

    def _arc_checks(self, step: Step, ins: Any) -> list[Diagnostic]:
        """A circular move whose orientation rule or circular angle this language cannot
        write (:attr:`ARC_ORIENTATIONS`, :attr:`ARC_ANGLE`)."""
        out = []
        if ins.orientation not in self.ARC_ORIENTATIONS:
            can = ", ".join(sorted(o.value for o in self.ARC_ORIENTATIONS))
            msg = (
                f"the {self.LANGUAGE} post cannot write a circular move whose orientation rule is "
                f"{ins.orientation.value!r} (it writes: {can})"
            )
            out.append(_error("arc_orientation", msg, step))
        if ins.angle is not None and not self.ARC_ANGLE:
            msg = (
                f"the {self.LANGUAGE} post cannot write a circular angle (CA): the arc would "
                "end at its programmed end point instead"
            )
            hint = "program the arc's real end point (and a second arc beyond 180°) instead"
            out.append(_error("arc_angle", msg, step, hint=hint))
        return out

    def _comment_checks(self, step: Step, comment: Any) -> list[Diagnostic]:
        try:
            lines = self.comment_lines(comment.text)
        except ValueError as exc:
            return [_error("comment", f"comment holds a {exc}: it cannot be written", step)]
        found = self._encoding_checks(step, "comment", "\n".join(lines))
        if not found or not comment.from_source:
            return found
        msg = (
            f"the program's comment {_quote(comment.text)} holds characters a "
            f"{self.manifest.encoding} {self.LANGUAGE} file cannot hold: written as '?'"
        )
        return [_warning("comment", msg, step)]

    def _flow_error(self, compiled: CompiledProgram) -> Diagnostic:
        from olp.ir_flow import FLOW_TYPES, leaves_and_blocks

        first = next(
            n for n in leaves_and_blocks(compiled.program.instructions) if isinstance(n, FLOW_TYPES)
        )
        what = first.kind.replace("_", " ")
        where = f"(first: {what} at line {first.span.line}); nothing of the program is written"
        if not self.WRITES_FLOW:
            message = f"the {self.LANGUAGE} post does not write control flow and data statements"
            return Diagnostic("error", "control_flow", f"{message} yet {where}", first.span)
        message = (
            f"the {self.LANGUAGE} post's template folder {self.manifest.folder.name} does not "
            "declare that it writes control flow and data statements (flow: true in its "
            f"post.yaml) {where}"
        )
        hint = (
            f"use the bundled {self.NAME} post, or a copy made since olp writes "
            f"{self.LANGUAGE} control flow"
        )
        return Diagnostic("error", "control_flow", message, first.span, hint=hint)

    def _verbatim_checks(self, step: Step, ins: Any) -> list[Diagnostic]:
        """A statement kept as source text goes out unchanged to its own language only; it was
        checked to be one line when made, so it cannot start another statement. One that
        matters only on its own language's controller (``native_only``) is left out of any
        other with a warning giving its reason; without one where this post writes what it
        does as the settings of a motion (``modelled``)."""
        if ins.language == self.VERBATIM:
            return self._encoding_checks(step, "verbatim", ins.text)
        if ins.modelled:
            return []
        what = f"{ins.language.upper()} statement {_quote(ins.text)} (line {ins.span.line})"
        if ins.native_only:
            msg = f"{what} is not written: {ins.reason}"
            return [Diagnostic("warning", "ignored", msg, ins.span, step.index)]
        if self.options.get("foreign_verbatim") == "drop":
            msg = (
                f"{what} is not written: foreign_verbatim: drop (olp build "
                "--drop-foreign-verbatim) leaves it out"
            )
            return [Diagnostic("warning", "verbatim_dropped", msg, ins.span, step.index)]
        msg = (
            f"{what} is kept verbatim because olp does not model it ({ins.reason}); the "
            f"{self.LANGUAGE} post cannot write it"
        )
        hint = (
            "write it for this controller by hand, remove it from the source program, or leave "
            "it out with a warning: olp build --drop-foreign-verbatim (the post option "
            "foreign_verbatim: drop)"
        )
        return [_error("verbatim", msg, step, hint=hint)]

    def _call_checks(self, step: Step, name: str, args: Sequence[str]) -> list[Diagnostic]:
        if not self.NAME_RULE.is_legal(name):
            msg = f"call of {_quote(name)}: not a legal {self.LANGUAGE} routine name"
            return [_error("call_name", msg, step, hint=self._name_hint())]
        for arg in args:
            if not self.CALL_ARGUMENTS.allows(arg):
                msg = (
                    f"call of {name}: argument {_quote(arg)} cannot be written in "
                    f"{self.LANGUAGE} (allowed: {self.CALL_ARGUMENTS.describe})"
                )
                return [_error("call_argument", msg, step)]
        return self._encoding_checks(step, "call", ",".join(args))

    def _name_hint(self) -> str:
        rule = self.NAME_RULE
        length = f", at most {rule.max_length} characters" if rule.max_length else ""
        return f"letters, digits and _, a letter first{length}, not a reserved word"

    @property
    def io_range(self) -> tuple[int, int] | None:
        """``IO_RANGE``, or the template folder's option ``io_range: [low, high]`` (a cell
        whose controller has more or fewer I/O than the class assumes)."""
        given = self.options.get("io_range")
        if given is None:
            return self.IO_RANGE
        low, high = (int(v) for v in given)
        return low, high

    def _io_checks(self, step: Step, kind: str, index: int) -> list[Diagnostic]:
        span = self.io_range
        if span is None or span[0] <= index <= span[1]:
            return []
        what = "output" if kind == "set_output" else "input"
        msg = (
            f"digital {what} {index} is outside the {self.LANGUAGE} controller's range "
            f"{span[0]}..{span[1]}"
        )
        return [_error("io_range", msg, step)]

    def _encoding_checks(self, step: Step, what: str, text: str) -> list[Diagnostic]:
        bad = encodable(text, self.manifest.encoding)
        if bad is None:
            return []
        msg = (
            f"{what} holds the character {show_character(bad)}, which a "
            f"{self.manifest.encoding} {self.LANGUAGE} file cannot hold"
        )
        return [_error(what, msg, step)]


def _bind(fn: Filter, post: Post) -> Filter:
    def bound(*args: Any, **kwargs: Any) -> Any:
        return fn(post, *args, **kwargs)

    bound.__name__ = getattr(fn, "__name__", "filter")
    bound.__doc__ = fn.__doc__
    return bound


_ACCELERATION_NAMES = {
    "linear_acceleration": "TCP path acceleration",
    "angular_acceleration": "orientation acceleration",
}


def _setting(steps: Sequence[Step], name: str) -> tuple[int, Step | None]:
    """How many path moves of ``steps`` set the :class:`~olp.ir.Speed` limit ``name``, and the
    first (a toolpath's rows counted from its arrays)."""
    from olp.compiled import PathBlock, items_of

    count, first = 0, None
    for item in items_of(steps):
        if isinstance(item, PathBlock):
            if getattr(item.node, _NODE_LIMITS[name]) is not None:
                count += len(item)
                first = first or item.step(0)
        elif (
            item.instruction.kind in ("linear", "circular")
            and getattr(item.instruction.speed, name) is not None
        ):
            count += 1
            first = first or item
    return count, first


_NODE_LIMITS = {
    "linear_acceleration": "acceleration",
    "angular_acceleration": "angular_acceleration",
}
"""The :class:`~olp.ir.LinearPath` field of each acceleration limit of its rows."""


def _error(kind: str, message: str, step: Step, hint: str | None = None) -> Diagnostic:
    return Diagnostic("error", kind, message, step.instruction.span, step.index, hint=hint)


_RELATIVE_WORDS = {
    "base": "offsets from its start position along and about the base's axes",
    "tool": "offsets from its start position in the tool frame",
    "axes": "offsets added to the axis values it starts at",
    "start": "a position whose components left out are those of its start position",
}


def _relative_refusal(language: str, what: str, ins: Any) -> str:
    """Why a post cannot write a run-time motion whose target refers to its start."""
    return (
        f"the {language} post cannot write {what}: its target is "
        f"{_RELATIVE_WORDS[ins.relative]}, which the robot reaches only at run time, and olp "
        f"writes that only in the source's own language"
    )


def _warning(kind: str, message: str, step: Step) -> Diagnostic:
    return Diagnostic("warning", kind, message, step.instruction.span, step.index)


def _quote(text: str, limit: int = 60) -> str:
    shown = text if len(text) <= limit else text[: limit - 3] + "..."
    return repr(shown)
