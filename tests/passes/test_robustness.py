"""Issue 10's reproductions, end to end through a frontend on the KR 6 milling cell: absurd but
parseable programs give located diagnostics, never a traceback or unbounded memory."""

from __future__ import annotations

from pathlib import Path

import pytest

from olp.api import build
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def _errors(station: Station, path: Path) -> list[tuple[str, int]]:
    result = build(station, path, post="kuka")
    assert not result.files
    return [(d.kind, d.span.line) for d in result.diagnostics if d.severity == "error" and d.span]


@pytest.mark.parametrize("far", ["1e40", "1e300", "100000400"])
def test_a_far_csv_target_is_unreachable_on_its_row(
    station: Station, tmp_path: Path, far: str
) -> None:
    """``x,y,z`` / ``400,0,500`` / ``400,0,1e40``: ValueError (negative dimensions); 100 km: a
    7 GB sample array and MemoryError."""
    program = tmp_path / "far.csv"
    program.write_text(f"x,y,z\n400,0,500\n400,0,{far}\n")
    assert _errors(station, program) == [("unreachable", 3)]


def test_a_tiny_krl_joint_speed_is_a_timing_error_on_the_ptp(
    station: Station, tmp_path: Path
) -> None:
    """``$VEL_AXIS[1] = 0.000001`` then a PTP: Ruckig's ``-101 is not a valid Result``."""
    program = tmp_path / "slow.src"
    program.write_text(
        "DEF slow()\n$VEL_AXIS[1] = 0.000001\nPTP {A1 10,A2 -90,A3 90,A4 0,A5 30,A6 0}\nEND\n"
    )
    assert _errors(station, program) == [("timing", 3)]


def _fuzz_module():  # type: ignore[no-untyped-def]
    """benchmarks/fuzz_passes.py, the long-run fuzzer, loaded by path (not a package)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "fuzz_passes", REPO / "benchmarks" / "fuzz_passes.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("seed", range(4))
def test_absurd_programs_give_diagnostics_not_exceptions(seed: int) -> None:
    """A short seeded run of the fuzzer (``python -m benchmarks.fuzz_passes`` runs long)."""
    crashes: list[str] = []
    _fuzz_module().run(15, seed, lambda k, text: crashes.append(f"program {k}: {text}"))
    assert crashes == []


def test_a_huge_zone_timed_as_a_stop_is_an_info_without_a_warning(station: Station) -> None:
    """A LIN with a 1e308 m zone before a PTP: the zone-stop note multiplied a numpy float by
    1000 and numpy warned of the overflow (found by benchmarks/fuzz_passes.py)."""
    import warnings

    import numpy as np

    from olp import ir

    at = station.robot.flange_poses(station.robot.home)
    moves = (
        ir.LinearMove(target=ir.CartesianTarget(pose=at), zone=ir.Zone(1e308)),
        ir.JointMove(target=ir.JointTarget(joints=station.robot.home + np.radians(5.0))),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = build(station, ir.Program(name="t", instructions=moves), post="kuka")
    notes = [d.message for d in result.diagnostics if d.kind == "zone_stop"]
    assert notes and notes[0].startswith("zone of inf mm timed as an exact stop")
