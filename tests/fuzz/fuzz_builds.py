"""A mutational fuzzer of whole builds: mutate real inputs, build, and allow only honest ends.

Inputs are the bundled examples and stations (KRL with its .dat, CSV toolpaths, station YAML),
mutated the way careless or hostile files look: lines deleted, duplicated or swapped, numbers
replaced by extreme values (0, -0, 1e308, 1e-320, 1e40, 400 digits, NaN and inf spelled as
text), control characters, non-UTF-8 bytes, CR, NUL, huge lines, truncation. Each mutant is built
(:func:`olp.build`, collisions and timing included) through a random post. An end is honest when
it is

* ``built``: no error diagnostic, files rendered;
* ``program``: error diagnostics (the program cannot run on the station), no files;
* ``input``: an :class:`olp.errors.OlpError` (a located input error; exit code 2).

Anything else (another exception) is a ``crash``: the mutant is saved with its traceback.

``run(count, seed)`` is used by ``tests/fuzz/test_fuzz.py`` (a short run in CI) and by
``benchmarks/fuzz_builds.py`` (a long run that prints its figures).
"""

from __future__ import annotations

import random
import time
import traceback
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]

SEEDS: dict[str, tuple[str, str, str | None]] = {
    # name: (station, program, companion .dat copied beside the program)
    "milling": ("stations/kr6_milling_cell.yaml", "examples/milling.src", None),
    "pendant_pick": (
        "stations/kr6_milling_cell.yaml",
        "examples/pendant_pick.src",
        "examples/pendant_pick.dat",
    ),
    "transpile": ("stations/ur5e_screw_cell.yaml", "tests/posts/transpile.src", None),
    "path_xyz": ("stations/kr6_milling_cell.yaml", "examples/path_xyz.csv", None),
    "targets_xyzwpr": ("stations/kr6_milling_cell.yaml", "examples/targets_xyzwpr.csv", None),
    "pick_irb120": ("stations/abb_irb120_pick_cell.yaml", "tests/posts/pick_irb120.src", None),
}
POSTS = ("kuka", "abb", "ur", "fanuc")

EXTREMES = [
    "0", "-0", "-0.0", "1e308", "-1e308", "1e-320", "1e40", "-1e40", "1e300", "4e-6",
    "9" * 400, "nan", "NaN", "inf", "-inf", "1e309", "0x10", "1_000", "+", "-", ".", "1.2.3",
    "", "''", "\"\"", "1e", "E5", "00000000001", "-999999999", "2147483648",
]  # fmt: skip
NASTY = [
    "\x00", "\r", "\n", "\r\n", "\t", "\x07", "\x1b[2J", "\x85", "\u2028", "\ufeff", "é",
    "\\", "\"", "'", ";", "{", "}", "[", "]", "{{ 7*7 }}", "{% raw %}", "${X}", "%s", "$(id)",
]  # fmt: skip


@dataclass
class Outcome:
    """How one mutant ended."""

    kind: str
    seed: str
    post: str
    mutations: list[str]
    detail: str = ""


@dataclass
class Report:
    """The figures of a run."""

    outcomes: list[Outcome] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def counts(self) -> Counter[str]:
        return Counter(o.kind for o in self.outcomes)

    @property
    def crashes(self) -> list[Outcome]:
        return [o for o in self.outcomes if o.kind == "crash"]


Mutator = Callable[[random.Random, str], tuple[str, str]]


def _lines(text: str) -> list[str]:
    return text.split("\n")


def _delete_line(rng: random.Random, text: str) -> tuple[str, str]:
    lines = _lines(text)
    k = rng.randrange(len(lines))
    return "\n".join(lines[:k] + lines[k + 1 :]), f"delete line {k + 1}"


def _duplicate_line(rng: random.Random, text: str) -> tuple[str, str]:
    lines = _lines(text)
    k = rng.randrange(len(lines))
    times = rng.choice([1, 2, 50])
    return "\n".join(lines[:k] + [lines[k]] * (times + 1) + lines[k + 1 :]), f"repeat line {k + 1}"


def _swap_lines(rng: random.Random, text: str) -> tuple[str, str]:
    lines = _lines(text)
    a, b = rng.randrange(len(lines)), rng.randrange(len(lines))
    lines[a], lines[b] = lines[b], lines[a]
    return "\n".join(lines), f"swap lines {a + 1} and {b + 1}"


def _number(rng: random.Random, text: str) -> tuple[str, str]:
    import re

    spots = [m.span() for m in re.finditer(r"[-+]?\d+(\.\d+)?([eE][-+]?\d+)?", text)]
    if not spots:
        return text, "no number"
    lo, hi = rng.choice(spots)
    value = rng.choice(EXTREMES)
    return text[:lo] + value + text[hi:], f"number at {lo} -> {value!r}"


def _insert(rng: random.Random, text: str) -> tuple[str, str]:
    k = rng.randrange(len(text) + 1)
    piece = rng.choice(NASTY)
    return text[:k] + piece + text[k:], f"insert {piece!r} at {k}"


def _huge_line(rng: random.Random, text: str) -> tuple[str, str]:
    lines = _lines(text)
    k = rng.randrange(len(lines))
    lines[k] = lines[k] + "," * rng.choice([10, 1000]) + "9" * rng.choice([100, 200_000])
    return "\n".join(lines), f"huge line {k + 1}"


def _truncate(rng: random.Random, text: str) -> tuple[str, str]:
    k = rng.randrange(len(text) + 1)
    return text[:k], f"truncate at {k}"


MUTATORS: tuple[Mutator, ...] = (
    _delete_line,
    _duplicate_line,
    _swap_lines,
    _number,
    _number,
    _number,
    _insert,
    _huge_line,
    _truncate,
)


def mutate(rng: random.Random, text: str, count: int) -> tuple[str, list[str]]:
    """``text`` after ``count`` random mutations, and what they were."""
    done = []
    for _ in range(count):
        text, what = rng.choice(MUTATORS)(rng, text)
        done.append(what)
    return text, done


def one(rng: random.Random, work: Path) -> Outcome:
    """Mutate one seed (the program, or now and then the station), build it, classify."""
    import olp
    from olp.errors import OlpError

    seed = rng.choice(sorted(SEEDS))
    station_path, program_path, dat = SEEDS[seed]
    post = rng.choice(POSTS)
    station_text = (REPO / station_path).read_text(encoding="utf-8")
    program_text = (REPO / program_path).read_text(encoding="utf-8", errors="replace")
    mutations: list[str] = []
    if rng.random() < 0.2:
        station_text, done = mutate(rng, station_text, rng.choice([1, 2, 3]))
        mutations += [f"station: {m}" for m in done]
    else:
        program_text, done = mutate(rng, program_text, rng.choice([1, 1, 2, 3, 5]))
        mutations += [f"program: {m}" for m in done]
    folder = work / f"case{rng.randrange(10**9)}"
    folder.mkdir(parents=True)
    station_file = folder / Path(station_path).name
    program_file = folder / Path(program_path).name
    encoding = "latin-1" if rng.random() < 0.05 else "utf-8"
    station_file.write_bytes(station_text.encode("utf-8", errors="surrogateescape"))
    program_file.write_bytes(program_text.encode(encoding, errors="replace"))
    if dat is not None:
        (folder / Path(dat).name).write_bytes((REPO / dat).read_bytes())
    _copy_meshes(station_path, folder)
    try:
        result = olp.build(olp.load_station(station_file), program_file, post=post)
    except OlpError as exc:
        return Outcome("input", seed, post, mutations, exc.format()[:300])
    except Exception:
        detail = traceback.format_exc()
        (folder / "traceback.txt").write_text(detail)
        return Outcome("crash", seed, post, mutations, detail)
    if result.ok:
        return Outcome("built", seed, post, mutations)
    return Outcome("program", seed, post, mutations)


def _copy_meshes(station_path: str, folder: Path) -> None:
    """Meshes a station names live beside it: copy the bundled ones so that a mutant of the
    station finds them where the original does."""
    source = (REPO / station_path).parent
    for mesh in source.glob("*.stl"):
        (folder / mesh.name).write_bytes(mesh.read_bytes())


def run(count: int, seed: int, work: Path, progress: Callable[[int], None] | None = None) -> Report:
    """Build ``count`` mutants from random seed ``seed`` in folder ``work``."""
    rng = random.Random(seed)
    report = Report()
    start = time.perf_counter()
    for k in range(count):
        report.outcomes.append(one(rng, work))
        if progress is not None:
            progress(k + 1)
    report.seconds = time.perf_counter() - start
    return report
