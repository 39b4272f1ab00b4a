"""USERS.md job 12: edit a program as data, one line per edit.

A library script (run it with ``python examples/edit_program.py``; it is not an olp program):
read the pick-and-place program of job 11, lower every TCP speed above 100 mm/s to 100 mm/s,
delete the dwells, put a ``LogStep`` call after each call, and build the result. Each edit
returns a new program; the instructions keep their source lines, so diagnostics still point
into the original file.
"""

from __future__ import annotations

from pathlib import Path

import olp
from olp import ir

HERE = Path(__file__).resolve().parent
LIMIT = 0.1  # m/s


def edit(program: ir.Program) -> ir.Program:
    """The three edits of job 12."""
    return (
        program.map_motions(lambda m: m.with_speed(linear=min(m.speed.linear, LIMIT)))
        .filter(lambda i: not isinstance(i, ir.Wait))
        .insert_after(lambda i: isinstance(i, ir.Call), lambda i: ir.Call(name="LogStep"))
    )


def main() -> None:
    station = olp.load_station(HERE.parent / "stations" / "kr6_milling_cell.yaml")
    parsed = olp.parse(HERE / "pick_and_place.py", station=station)
    result = olp.build(station, edit(parsed.program), post="kuka", out_dir="out/edited")
    for diagnostic in result.diagnostics:
        print(diagnostic.format())
    print(f"{len(result.written)} files written, cycle time {result.compiled.cycle_time:.2f} s")


if __name__ == "__main__":
    main()
