"""KUKA KRL frontend (KR C4, KSS 8): a ``.src`` program (+ its ``.dat``) -> :class:`olp.ir.Program`.

Pipeline: :mod:`~olp.frontends.krl.parse` (grammar ``grammars/krl.lark``, LALR, positions
propagated; simple motion lines through the fast path of :mod:`~olp.frontends.krl.fast`) ->
:mod:`~olp.frontends.krl.ast` nodes -> :mod:`~olp.frontends.krl.lower` (tracks the controller's
motion state) -> IR. Data lists (the module's ``.dat``, a ``$config.dat``) are read by
:mod:`~olp.frontends.krl.data`; constant expressions are evaluated by
:mod:`~olp.frontends.krl.values`.

What is lowered
---------------
* **Comments.** Every comment and pendant fold line is kept in place as
  :class:`olp.ir.Comment` (``fold`` for ``;FOLD``/``;ENDFOLD``, as written), at every level
  (:mod:`~olp.frontends.krl.comments`); the pendant's ``$BWDSTART`` and the lines of the
  source's INI fold are kept for the KRL post alone (:mod:`~olp.frontends.krl.native`).
* **Files.** ``&`` header lines, several ``DEF``/``DEFFCT`` routines, ``;FOLD`` comments. The
  first ``DEF`` is the program (a module of ``DEFFCT`` functions only is an empty program
  holding the functions as routines). Declarations may leave out ``DECL`` for the simple and the
  predefined structure types (``FRAME lfOffset``, ``E6AXIS XHOME={...}``, as a controller's
  ``$config.dat`` writes them); parameters may be arrays (``sText[]:IN``) and functions may
  return one (``DEFFCT CHAR[128]``). :func:`load_krl` reads the ``.dat`` beside the ``.src`` (same
  name, any case) and, if given, the controller's ``$config.dat``; their ``DECL``\\ s with values
  (``E6POS/POS/FRAME/E6AXIS/AXIS``, ``PDAT/LDAT/FDAT``, numbers, ...) and value assignments
  (``TOOL_DATA[1]={...}``, ``TOOL_NAME[1,]="..."``) are the program's global variables; the
  module's ``.dat`` wins over ``$config.dat``. Other modules' data lists (``data_lists``,
  ``data_lists_from``: a shared ``Positions.dat``) add the names they declare ``GLOBAL`` in a
  ``DEFDAT ... PUBLIC`` (:func:`olp.frontends.krl.data.visible_globals`: the module's own names
  hide them; a global name declared twice is an error naming both places).
* **Motions.** ``PTP``/``LIN``/``CIRC`` and ``SPTP``/``SLIN``/``SCIRC`` (lowered alike) to inline
  aggregates or named points (``PTP XP1``, ``PTP XHOME``, ``PTP $H_POS``). Axis values (degrees)
  become a :class:`~olp.ir.JointTarget` (all of A1..A6 needed); ``{X, Y, Z, A, B, C}`` (mm, deg)
  the TCP pose in the current ``$BASE`` (:func:`olp.vendors.kuka.frame_to_pose`). Components
  left out are taken from the previous Cartesian target in the program text, as long as no
  motion to axis values, ``$BASE`` or ``$TOOL`` change came in between (else olp says it cannot
  know them). ``S``/``T`` are recorded in :attr:`KrlResult.status_turn`; a PTP target with both
  gets ``config=`` :func:`olp.vendors.kuka.configuration_from_status_turn` ``(S, T)``. LIN/CIRC
  targets get none: the controller ignores S/T there (the branch follows from the start), so olp
  must not enforce one. A named point gives its name to the target (``name == "XP1"``).
* **_REL motions** are made absolute when the start is known from the program text:
  ``PTP_REL {A1 10}`` from the previous axis values, Cartesian offsets from the previous
  Cartesian target, in ``#BASE`` (default: positions add along the base axes and the rotation
  is applied about them at the TCP) or ``#TOOL`` (start · offset); else an error says why.
  The #BASE reading of a rotation offset is olp's, unverified against a controller.
* **Approximation.** None: exact stop (:data:`olp.ir.FINE`). ``C_DIS``/``C_SPL`` use the current
  ``$APO.CDIS`` (mm) as the zone radius; ``C_PTP`` (KRL: ``$APO.CPTP`` in %) and ``C_VEL``/
  ``C_ORI`` use the same distance (``C_VEL``/``C_ORI`` add a note). The inline forms' doubled
  ``C_DIS C_DIS`` reads as ``C_DIS``; ``PTP XP1 C_DIS`` (what the PTP inline form writes with
  CONT since KSS 8.2: the distance criterion) uses ``$APO.CDIS`` too. Before any ``$APO.CDIS``
  a motion stops exactly, with a note.
* **Motions to run-time targets** (a position computed from a function's result, an input, a
  routine parameter or a path-dependent value, all of its names declared: ``LIN xPath[i]``,
  ``PTP fnGetPos()``) become :class:`olp.ir.RuntimeMove`: the target stays the expression, the
  tool, base, speed and approximation are those in effect (the posts write them before it as
  before any motion), and ``reason`` says why olp cannot know the target. The passes warn that
  they cannot check or time it, and the next motion starts where olp does not know. A
  ``_REL`` motion by run-time offsets is a run-time motion with ``relative`` saying how its
  target refers to the start (a ``PTP_REL`` by a variable: by the type its ``DECL`` gives,
  axes or position; of an undeclared type it is kept as written, :class:`olp.ir.Verbatim`,
  only right after a modelled PTP with the same settings in the same straight stretch). A
  motion whose target refers to its start position (``LIN_REL {Z 50}``, ``PTP_REL {A6 15}``,
  ``LIN {Z 500}``) right where a run-time motion left the robot, or first in a program that
  takes parameters or that an ``INTERRUPT DECL`` of the module runs (it starts where its
  caller, or the interrupt, left the robot), is a run-time motion too, its target the
  expression and ``relative`` saying how it refers to the start (only KRL writes it).
* **Names no file olp read declares.** Where a file the controller would find a name in was
  not given (the module's ``.dat`` is not beside the ``.src``, or no ``$config.dat``), such a
  name is a value known only when the program runs, never guessed: a warning per name at its
  first use says which files are missing and that olp cannot check what depends on it (a
  misspelling looks the same); motions to it are run-time motions (``PTP XHOME`` without
  ``$config.dat``: the reason names the file), a BAS reading an inline-form record of it
  (``FDAT_ACT = FHOME``) is kept as written, and ``$BASE``/``$TOOL`` set from it are kept as
  written and leave the base (tool) unknown: a motion before it is set again is an error.
  With every such file given, a name declared nowhere is an error where olp needs its value
  (naming the data list that would declare it) and a warning elsewhere: the controller's
  compiler refuses it. A function that no ``DEFFCT`` of the module, ``EXTFCT`` or KRL system
  function declares is written as it stands, with a warning
  (:mod:`olp.frontends.krl.declared`).
* **BAS with run-time values** (``BAS(#PTP_PARAMS, v)``, or ``PDAT_ACT`` given a parameter) is
  kept as written; the settings it sets are ambiguous until set again, and a motion that runs
  with one of them (a PTP: tool, base, axis speeds and accelerations; a LIN/CIRC: tool, base,
  path speed, ``$ORI_TYPE``/``$CIRC_TYPE``; an approximated one: ``$APO.CDIS``) is an error
  naming them (the output would not write the settings that BAS changed behind its back),
  except the motion right after the BAS commands of one straight stretch (the pendant's HOME
  fold): a run-time motion with the controller's settings, the settings statements olp
  absorbed since the first of those BAS kept as written before it. A settings routine without
  motions builds.
* **Motion settings from run-time values** (``$VEL.CP = rProbeSpeed``, ``$ACC.CP = acc`` with
  ``acc`` a parameter, ``$VEL_AXIS[i] = scale * 100``, ``$APO.CDIS``, ``$ORI_TYPE``,
  ``$BASE = BASE_DATA[nBase]``) are kept as written (another post refuses them) and hold that
  setting (:class:`~olp.frontends.krl.state.Held`; the speed part by part,
  :data:`~olp.frontends.krl.state.SPEED_PARTS`): a motion that runs with it before the program
  sets it again runs with the controller's settings, unchecked and untimed. One computed from
  the counter of a FOR loop with constant bounds is not: the loop is unrolled.
* **Unrolled FOR loops** write ``counter = n`` before a pass whose output reads the counter
  (a run-time motion such as ``LIN xPath[i]``, a statement kept as written such as
  ``r[i] = $OV_PRO``, ``Foo(i)``). One whose body only sets motion settings olp models
  (``FOR ax = 1 TO 6 $VEL_AXIS[ax] = 20 ENDFOR``) is unrolled into the settings and kept as
  written where it stands, as KRL-only lines: the KUKA post writes the loop, then the next
  motion's settings again (olp's values); other posts write those settings with the motion,
  and leave the loop out without a warning where a motion olp models follows it
  (:attr:`olp.ir.Verbatim.modelled`), with one where none does.
* **Speeds.** ``$VEL.CP`` (m/s) -> ``Speed.linear``; ``$VEL_AXIS[i]``/``$ACC_AXIS[i]`` (%) ->
  ``Speed.joint``/``joint_acceleration`` as the **minimum** over the axes set so far (one
  fraction cannot hold per-axis values; the slowest axis bounds a synchronised PTP).
  ``$VEL``/``$APO`` aggregates are read component by component. Before any ``$VEL.CP`` olp
  assumes :data:`DEFAULT_VEL_CP` (noted once).
* **Tool and base.** ``$BASE``/``$TOOL`` = ``{FRAME: ...}`` (missing components are 0; named
  ``base_l<line>``/``tool_l<line>``, or after the variable holding it); ``BASE_DATA[n]``/
  ``TOOL_DATA[n]`` -> with a ``$config.dat``: its value, named ``BASE_NAME[n,]``/``TOOL_NAME[n,]``
  (else ``"TOOL_DATA[n]"``), number ``n``; a number missing there is an error. Without one:
  the reference ``Tool(name="TOOL_DATA[n]", number=n, pose=None)`` the station resolves by
  number. ``$NULLFRAME`` and number 0 -> :data:`olp.ir.WORLD`/:data:`olp.ir.FLANGE`.
* **Inline forms (KUKATPBASIS, KSS 8).** The ``;FOLD PTP P1 Vel=100 % PDAT1 Tool[1] Base[0]``
  comment is a fold comment, kept; the lines inside it are lowered: ``PDAT_ACT=PPDAT1``/
  ``LDAT_ACT=...``/``FDAT_ACT=FP1`` (assignments), ``BAS(#PTP_PARAMS, v)`` (FDAT_ACT's TOOL_NO,
  BASE_NO, IPO_FRAME; joint speed ``v`` %, PDAT_ACT's ACC % and APO_DIST mm), ``BAS(#CP_PARAMS, v)``
  (frames; ``$VEL.CP = v`` m/s, LDAT_ACT's APO_DIST mm), ``$H_POS=XHOME`` (also kept as written: the
  controller's home for its ``$IN_HOME`` output), the motion. An FDAT with ``IPO_FRAME #TCP``
  (a stationary tool, the robot carrying the part) is not modelled: its BAS is kept as written
  and the motion after it is a run-time motion with the controller's settings (not checked).
  ``BAS(#FRAMES|#PTP_DAT|#CP_DAT|#VEL_CP|#VEL_PTP|#ACC_PTP|#TOOL|#BASE, ...)`` likewise. The spline
  inline forms' ``WITH $VEL_AXIS[1] = SVEL_JOINT(100.0), $TOOL = STOOL2(FP1), $BASE =
  SBASE(FP1.BASE_NO), $APO = SAPO_PTP(PPDAT1), ...`` are read, for that motion only. This follows
  KUKA's documented meaning of BAS and the inline forms; it is not verified against ``BAS.SRC`` or a
  controller (which of the BAS value and PDAT VEL wins, and whether WITH values outlast their
  motion, are the main open questions).
* **Routines and calls.** The module's other ``DEF``/``DEFFCT`` routines are
  :class:`~olp.ir.Routine`\\ s of the program (:attr:`olp.ir.Program.routines`): parameters
  with their direction (``:IN`` by value, ``:OUT`` or no mark by reference) and the type their
  ``DECL`` gives, local declarations, the result type of a ``DEFFCT`` and ``RETURN value``,
  ``GLOBAL``. A call of a ``DEF`` is lowered at each call from the state there (parameters by
  value where the arguments are constant; others are unknown inside; parameters not marked
  ``:IN`` are copied back to a plain variable argument), then kept as an
  :class:`~olp.ir.RoutineCall` where every call lowered the same routine
  (:mod:`olp.frontends.krl.routines`; where the calls differ only in why a motion runs with
  the controller's settings, the routine lowered from an unknown caller's state; otherwise
  written out at its calls with a warning); recursion is an error. Checks see each routine's
  body at every call (:meth:`olp.ir.Program.expanded`). Routines no call reaches (interrupt
  handlers, functions, a library's routines other modules or the PLC call) are lowered from an
  unknown caller's state (every motion setting the controller's, the robot where olp does not
  know, the module's variables known only where nothing in it changes them) and kept, with a
  note where they move the robot: a plain motion runs with the controller's settings, an
  inline form's is modelled, its target checked from an unknown start
  (:attr:`olp.ir_flow.Expanded.entry`). Other calls become :class:`~olp.ir.Call` (arguments as
  source text). The program's own parameters (``DEF MoveSettings(nBase:IN, nTool:IN)``, a
  module other modules call) are :attr:`olp.ir.Program.params`, typed the same way; their
  values are the caller's, known only when the program runs.
* **Control flow** becomes :mod:`olp.ir_flow` blocks (re-exported from :mod:`olp.ir`): ``IF``
  -> :class:`~olp.ir.If`, ``SWITCH`` -> :class:`~olp.ir.Switch`, ``WHILE``/``REPEAT``/``LOOP``
  -> :class:`~olp.ir.While`/:class:`~olp.ir.Repeat`/:class:`~olp.ir.Loop`, ``EXIT`` ->
  :class:`~olp.ir.Exit`, labels and ``GOTO`` -> :class:`~olp.ir.Label`/:class:`~olp.ir.Goto`,
  conditions as :mod:`olp.ir_flow` expressions. Each body is lowered from the state that
  reaches it; after a block, a variable keeps its value only where every path agrees, and a
  motion setting (speed, zone, tool, base) that differs between the paths is an error at the
  next motion that relies on it (the inline forms set them again, so pendant programs pass). A
  loop's body starts from the join of the state before it and after a pass (variables it
  assigns are unknown inside; one without a value before the loop holds, from the run, what
  an earlier pass left: ``LOOP SWITCH cmd CASE 1 LIN p ... CASE 2 p = ...``). ``FOR`` loops
  with constant integer bounds over straight-line code are unrolled where a target depends on
  the counter (at most :data:`~olp.frontends.krl.lower.MAX_FOR_ITERATIONS` iterations, and
  :data:`~olp.frontends.krl.lower.MAX_LOWERED_STATEMENTS` statements in all); others are a
  :class:`~olp.ir.For` block; a statement after an unrolled loop that reads its counter is an
  error (the value KRL leaves in it is not written: :class:`olp.frontends.krl.flow.PastFor`).
  A jump back to a label makes the variables the routine assigns
  unknown there; one with other motion settings than the label had is an error. ``SPLINE ...
  ENDSPLINE`` blocks are rejected. ``RETURN`` inside a block of a called routine ends that
  path of the routine (:class:`~olp.ir.Return`); the caller goes on from the join of the
  routine's end and its RETURNs.
* **Motions to where the robot is** (``PTP $POS_ACT``, ``PTP $AXIS_ACT``: the block
  coincidence run) are kept as written (:class:`olp.ir.Verbatim`): there is nothing to check.
  A motion to a value derived from them at run time (``lNow.Z = lNow.Z + 100``, ``LIN lNow``)
  is a motion to a run-time target (above).
* **Data.** Declarations in the program are :class:`~olp.ir.Declare`, assignments of the
  program's variables :class:`~olp.ir.Assign` (their constant values are also used, as before);
  what the inline forms assign for BAS (``PDAT_ACT``, ``LDAT_ACT``, ``FDAT_ACT``) is absorbed
  into the motions. ``WAIT FOR`` a condition other than an input is :class:`~olp.ir.WaitUntil`.
* **I/O and waits.** ``WAIT SEC`` -> Wait; ``WAIT FOR $IN[n]`` (or ``NOT``, ``== TRUE/FALSE``, a
  one-bit ``SIGNAL``) -> WaitInput; ``$OUT[n] = TRUE/FALSE`` (or a SIGNAL) -> SetOutput.
* **Variables.** Constant expressions are evaluated (KRL rules: INT/INT truncates); assignments
  of constants are kept for later use; others make the variable unknown and are listed.

Nothing is dropped silently: every statement olp recognised but did not lower is in
:attr:`KrlResult.ignored` with the reason (also those of the data lists; the frontend reports
the program's own as warnings). Statements that matter to the controller but that olp does not
model (motion parameters such as ``$ACC.CP``, ``$VEL.ORI1``, ``$ADVANCE``; ``SET_CD_PARAMS``,
``PULSE``, ``HALT``, ``BRAKE``, ``CONTINUE``, ``ON_ERROR_PROCEED``, ``RESUME``, motions to
``$POS_ACT``, ``PTP_REL`` by run-time offsets of an unknown type) are kept in the program as
:class:`olp.ir.Verbatim`: the KRL post writes them
back, other posts stop on them. ``$ORI_TYPE``/``$CIRC_TYPE`` are motion settings (the arcs'
orientation rule); for linear moves olp notes at each one that it does not model them.

Text the grammar does not accept, and values olp needs but cannot use, raise
:class:`olp.errors.ParseError` with file, line, column, what was expected and the offending text.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from olp import ir
from olp.errors import UsageError
from olp.frontends.krl.ast import IgnoredLine, Note, Source, SourceSet, StatusTurn
from olp.frontends.krl.data import KrlData, read_data_list
from olp.frontends.krl.lower import DEFAULT_VEL_CP, KrlResult, lower_module
from olp.frontends.krl.parse import gc_paused, parse_module

__all__ = [
    "DEFAULT_VEL_CP",
    "IgnoredLine",
    "KrlData",
    "KrlResult",
    "Note",
    "StatusTurn",
    "find_dat",
    "find_data_lists",
    "load_config_dat",
    "load_data_list",
    "load_krl",
    "parse_dat",
    "parse_krl",
]


def parse_krl(
    text: str,
    filename: str = "<string>",
    *,
    dat: KrlData | None = None,
    config: KrlData | None = None,
    shared: Sequence[KrlData] = (),
    fast_path: bool = True,
    calls_keep_settings: Sequence[str] = (),
) -> KrlResult:
    """Parse KRL source ``text`` (a ``.src`` file's content) and lower its first DEF.

    ``dat``: the module's data list (:func:`parse_dat`); ``config``: the controller's
    ``$config.dat`` (:func:`load_config_dat`); ``shared``: other modules' data lists, whose
    ``GLOBAL`` names of a ``PUBLIC`` list the program sees
    (:func:`olp.frontends.krl.data.visible_globals`). ``fast_path=False`` reads every line with
    the full grammar (same result, slower; for tests and benchmarks). ``calls_keep_settings``:
    routines olp does not read that leave the settings and the robot as they were
    (:class:`olp.frontends.bundled.KrlOptions`).

    Raises :class:`olp.errors.ParseError` (with span and source line) for text that is not KRL
    olp understands; no other exception escapes for bad input.
    """
    source = Source.of(text, filename)
    data = [d for d in (config, *shared, dat) if d is not None]
    sources = SourceSet([source, *(d.source for d in data)])
    try:
        with gc_paused():
            module = parse_module(source, fast=fast_path)
            return lower_module(
                module, sources, filename, dat, config, shared, tuple(calls_keep_settings)
            )
    except RecursionError:
        span = ir.SourceSpan(source.filename, 1, 1)
        raise source.error("the program is nested too deeply to read", span) from None


def load_krl(
    path: str | os.PathLike[str],
    config_dat: str | os.PathLike[str] | KrlData | None = None,
    data_lists: Sequence[str | os.PathLike[str] | KrlData] = (),
    data_lists_from: str | os.PathLike[str] | None = None,
    calls_keep_settings: Sequence[str] = (),
) -> KrlResult:
    """Read a ``.src`` file, the ``.dat`` beside it (:func:`find_dat`), an optional
    ``$config.dat`` (a path, or one read before with :func:`load_config_dat`) and other
    modules' data lists: ``data_lists`` (each must be ``PUBLIC``: :func:`load_data_list`) and
    the ``PUBLIC`` ones found under the folder ``data_lists_from`` (:func:`find_data_lists`).
    The module's own ``.dat`` is never read twice. ``calls_keep_settings``: see
    :func:`parse_krl`.

    Files are UTF-8, else Windows-1252 (what KUKA controllers write), else Latin-1.
    Raises :class:`olp.errors.UsageError` if a file cannot be read and
    :class:`olp.errors.ParseError` for its content.
    """
    config = config_dat if isinstance(config_dat, KrlData) or config_dat is None else None
    if config_dat is not None and config is None:
        config = load_config_dat(config_dat)  # type: ignore[arg-type]
    dat_path = find_dat(path)
    dat = None if dat_path is None else parse_dat(_read(dat_path, "data list"), os.fspath(dat_path))
    shared = _shared_lists(data_lists, data_lists_from, dat_path)
    return parse_krl(
        _read(path, "KRL"),
        os.fspath(path),
        dat=dat,
        config=config,
        shared=shared,
        calls_keep_settings=calls_keep_settings,
    )


def load_config_dat(path: str | os.PathLike[str]) -> KrlData:
    """Read a controller's ``$config.dat`` (TOOL_DATA, BASE_DATA, XHOME, FHOME, PDEFAULT, ...)."""
    return parse_dat(_read(path, "$config.dat"), os.fspath(path))


def parse_dat(text: str, filename: str = "<dat>") -> KrlData:
    """Read a data list's text (``DEFDAT ... ENDDAT``); :class:`ParseError` if it is not one."""
    try:
        return read_data_list(text, filename)
    except RecursionError:
        span = ir.SourceSpan(filename, 1, 1)
        raise Source.of(text, filename).error("the data list is nested too deeply", span) from None


def find_dat(path: str | os.PathLike[str]) -> Path | None:
    """The ``.dat`` beside a ``.src``: same name, the exact spelling first, else any case.

    Raises :class:`UsageError` if several files match only by case (``Pick.dat``, ``PICK.DAT``).
    """
    src = Path(path)
    exact = src.with_suffix(".dat")
    if exact.is_file():
        return exact
    wanted = exact.name.lower()
    try:
        matches = sorted(p for p in src.parent.iterdir() if p.name.lower() == wanted)
    except OSError:
        return None
    if len(matches) > 1:
        names = ", ".join(p.name for p in matches)
        raise UsageError(f"several data lists match {src.name}: {names}")
    return matches[0] if matches and matches[0].is_file() else None


def load_data_list(path: str | os.PathLike[str] | KrlData) -> KrlData:
    """Another module's data list, read for the names it declares ``GLOBAL``: a
    :class:`ParseError` at its ``DEFDAT`` line unless it is ``DEFDAT name PUBLIC`` (only a
    public list shares names; ``$config.dat`` is given as ``config_dat`` instead)."""
    data = (
        path if isinstance(path, KrlData) else parse_dat(_read(path, "data list"), os.fspath(path))
    )
    if not data.public:
        lines = enumerate(data.source.lines, 1)
        line = next((n for n, text in lines if text.lstrip().upper().startswith("DEFDAT")), 1)
        span = ir.SourceSpan(data.filename, line, 1)
        config = data.name.upper() == "$CONFIG"
        raise data.source.error(
            f"DEFDAT {data.name} is not PUBLIC: other modules do not see its names",
            span,
            hint="give the controller's $config.dat with --config-dat"
            if config
            else "only the GLOBAL declarations of a DEFDAT ... PUBLIC list are shared",
        )
    return data


def find_data_lists(folder: str | os.PathLike[str]) -> list[Path]:
    """The ``.dat`` files under ``folder`` (any depth, any case of the suffix), sorted, without
    ``$config.dat`` (given with ``config_dat``); :class:`UsageError` if it is not a folder."""
    root = Path(folder)
    if not root.is_dir():
        raise UsageError(f"cannot read data lists from {os.fspath(folder)!r}: not a folder")
    found = (p for p in root.rglob("*") if p.suffix.lower() == ".dat" and p.is_file())
    return sorted(p for p in found if p.name.lower() != "$config.dat")


def _shared_lists(
    given: Sequence[str | os.PathLike[str] | KrlData],
    folder: str | os.PathLike[str] | None,
    own: Path | None,
) -> list[KrlData]:
    """The data lists of ``given`` and the public ones under ``folder``, each file once and
    without the module's own ``.dat`` (``own``), whose names are the module's anyway."""
    seen = set() if own is None else {own.resolve()}
    lists = []
    for item in given:
        if _once(Path(item.filename if isinstance(item, KrlData) else item), seen):
            lists.append(load_data_list(item))
    for found in find_data_lists(folder) if folder is not None else ():
        if _once(found, seen):
            data = parse_dat(_read(found, "data list"), os.fspath(found))
            lists.extend([data] if data.public else [])
    return lists


def _once(path: Path, seen: set[Path]) -> bool:
    """Whether ``path`` is new to ``seen`` (and add it)."""
    key = path.resolve()
    new = key not in seen
    seen.add(key)
    return new


def _read(path: str | os.PathLike[str], what: str) -> str:
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise UsageError(f"cannot read {what} file {os.fspath(path)!r}: {exc.strerror}") from None
    return _decode(data)


def _decode(data: bytes) -> str:
    for encoding in ("utf-8", "cp1252"):
        try:
            return data.decode(encoding)
        except UnicodeDecodeError:
            continue
    return data.decode("latin-1")
