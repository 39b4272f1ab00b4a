"""A small interpreter of the LS lines the Fanuc post writes for control flow, for tests: it runs
a program's /MN section against given digital inputs and returns what it did, so that a test
can compare the lowering's result with what the KRL source means.

Semantics as :mod:`olp.posts.fanuc_flow` documents them (FOR per the FANUC manual: the counter
takes the start value, the body runs when start <= stop (TO), ENDFOR repeats while the counter
is below the stop and adds 1). It knows only the lines olp writes; any other line fails the
test, so it also checks that every jump lands on exactly one label.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field

_LINE = re.compile(r"^ *\d+:(.*)$")
_REF = re.compile(r"\b(R|PR|LBL)\[(\d+)(?:,(\d+))?(?::[A-Za-z0-9_]*)?\]")


@dataclass
class Run:
    """What a program did: ``trace`` (``DO[n]=ON``, ``move P[n]``, ``WAIT ...`` in order),
    ``r`` (numeric registers), ``pr`` (position register components)."""

    trace: list[str] = field(default_factory=list)
    r: dict[int, float] = field(default_factory=dict)
    pr: dict[tuple[int, int], float] = field(default_factory=dict)


def mn_lines(text: str) -> list[str]:
    """The /MN lines of an LS file without their numbers."""
    body = text.replace("\r\n", "\n").split("/MN\n")[1].split("\n/POS")[0]
    out = []
    for line in body.split("\n"):
        match = _LINE.match(line)
        assert match, line
        out.append(match.group(1).strip())
    return out


def run(text: str, inputs: Mapping[int, bool], limit: int = 10_000) -> Run:
    """Run the /MN section of ``text`` with digital inputs ``inputs`` (missing: OFF)."""
    lines = mn_lines(text)
    labels: dict[int, int] = {}
    for k, line in enumerate(lines):
        m = re.fullmatch(r"LBL\[(\d+)(?::\w*)?\] ;", line)
        if m:
            assert int(m.group(1)) not in labels, f"LBL[{m.group(1)}] twice"
            labels[int(m.group(1))] = k
    for line in lines:
        for target in re.findall(r"JMP LBL\[(\d+)\]", line):
            assert int(target) in labels, f"JMP to a missing LBL[{target}]"
    state = Run()
    fors: list[tuple[int, int, int, int]] = []  # (line of FOR, register, stop, step)
    pc, steps = 0, 0
    while pc < len(lines):
        steps += 1
        assert steps < limit, "the program does not end"
        line = lines[pc]
        pc += 1
        if line.startswith("SELECT"):
            pc = _select(lines, pc - 1, state, labels)
            continue
        if m := re.fullmatch(r"JMP LBL\[(\d+)\] ;", line):
            pc = labels[int(m.group(1))]
        elif m := re.fullmatch(r"IF (.*),JMP LBL\[(\d+)\] ;", line):
            if _truth(m.group(1), state, inputs):
                pc = labels[int(m.group(2))]
        elif m := re.fullmatch(r"FOR (.*)=(.*) (TO|DOWNTO) (.*) ;", line):
            reg, start = _reg(m.group(1)), _value(m.group(2), state)
            stop = _value(m.group(4), state)
            step = 1 if m.group(3) == "TO" else -1
            state.r[reg] = start
            if (start - stop) * step > 0:
                pc = _matching_endfor(lines, pc - 1) + 1
            else:
                fors.append((pc - 1, reg, int(stop), step))
        elif line == "ENDFOR ;":
            start_line, reg, stop, step = fors[-1]
            if (state.r[reg] - stop) * step < 0:
                state.r[reg] += step
                pc = start_line + 1
            else:
                fors.pop()
        elif m := re.fullmatch(r"WAIT (.*) ;", line):
            if not m.group(1).endswith("(sec)"):
                assert _truth(m.group(1), state, inputs), f"waits for ever: {line}"
            state.trace.append(line[:-2])
        elif m := re.fullmatch(r"DO\[(\d+)\]=(ON|OFF) ;", line):
            state.trace.append(f"DO[{m.group(1)}]={m.group(2)}")
        elif m := re.fullmatch(r"[JLC] P\[(\d+)\].*", line):
            state.trace.append(f"move P[{m.group(1)}]")
        elif line == "END ;":
            break
        elif m := re.fullmatch(r"(R\[[^]]*\]|PR\[\d+,\d\])=(.*) ;", line):
            _store(m.group(1), _value(m.group(2), state), state)
        elif m := re.fullmatch(r"PR\[(\d+)(?::\w*)?\]=PR\[(\d+)(?::\w*)?\] ;", line):
            for j in range(1, 7):
                state.pr[(int(m.group(1)), j)] = state.pr.get((int(m.group(2)), j), 0.0)
        elif not (
            re.fullmatch(r"LBL\[\d+(?::\w*)?\] ;", line)
            or re.fullmatch(r"U(FRAME|TOOL)_NUM=\d+ ;", line)
            or line.startswith("!")
        ):
            raise AssertionError(f"the LS machine does not know {line!r}")
    return state


def _select(lines: list[str], k: int, state: Run, labels: Mapping[int, int]) -> int:
    subject = _value(re.match(r"SELECT (R\[[^]]*\])=", lines[k]).group(1), state)  # type: ignore[union-attr]
    while True:
        line = lines[k].removeprefix("SELECT ").strip()
        if m := re.fullmatch(r"(?:R\[[^]]*\])?=(\d+),JMP LBL\[(\d+)\] ;", line):
            if subject == int(m.group(1)):
                return labels[int(m.group(2))]
        elif m := re.fullmatch(r"ELSE,JMP LBL\[(\d+)\] ;", line):
            return labels[int(m.group(1))]
        else:
            raise AssertionError(f"not a SELECT line: {line!r}")
        k += 1


def _matching_endfor(lines: list[str], k: int) -> int:
    depth = 0
    for j in range(k, len(lines)):
        depth += lines[j].startswith("FOR ") - (lines[j] == "ENDFOR ;")
        if depth == 0:
            return j
    raise AssertionError("FOR without ENDFOR")


def _reg(text: str) -> int:
    m = re.fullmatch(r"R\[(\d+)(?::\w*)?\]", text)
    assert m, text
    return int(m.group(1))


def _store(target: str, value: float, state: Run) -> None:
    m = _REF.fullmatch(target)
    assert m, target
    if m.group(1) == "R":
        state.r[int(m.group(2))] = value
    else:
        state.pr[(int(m.group(2)), int(m.group(3)))] = value


def _python(text: str, state: Run, inputs: Mapping[int, bool]) -> str:
    """An LS value or condition as a Python expression over ``state`` and ``inputs``."""

    def ref(m: re.Match[str]) -> str:
        number = int(m.group(2))
        if m.group(1) == "R":
            return repr(state.r.get(number, 0.0))
        return repr(state.pr.get((number, int(m.group(3))), 0.0))

    text = _REF.sub(ref, text)
    text = re.sub(r"DI\[(\d+)\]", lambda m: repr(bool(inputs.get(int(m.group(1)), False))), text)
    text = text.replace("<>", "!=").replace("<=", "__LE__").replace(">=", "__GE__")
    text = text.replace("=", "==").replace("__LE__", "<=").replace("__GE__", ">=")
    text = text.replace("ON", "True").replace("OFF", "False")
    return text.replace(" AND ", " and ").replace(" OR ", " or ")


def _value(text: str, state: Run) -> float:
    return float(eval(_python(text, state, {}), {"__builtins__": {}}))


def _truth(text: str, state: Run, inputs: Mapping[int, bool]) -> bool:
    return bool(eval(_python(text, state, inputs), {"__builtins__": {}}))
