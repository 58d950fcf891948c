"""The structural-conversion share on the real corpus (bench/bench_structure.py measures it for
`make bench`; here it is held, not timed). The issue's goals are ISO -> Sinumerik >= 85% and
Sinumerik -> ISO >= 80%; the floors below are what is reached now, so a change that loses ground
fails here. Raise them as the share grows."""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

from conftest import CORPUS

# One xdist worker runs this module (make test: --dist loadgroup): its tests read one module fixture
# (every corpus program converted both ways, ~10 s), which a split computes on each worker.
pytestmark = pytest.mark.xdist_group("structure-share")

_SPEC = importlib.util.spec_from_file_location(
    "bench_structure", Path(__file__).resolve().parents[1] / "bench" / "bench_structure.py")
bench_structure = importlib.util.module_from_spec(_SPEC)
sys.modules["bench_structure"] = bench_structure        # its dataclasses look their module up
_SPEC.loader.exec_module(bench_structure)

FLOORS = {("iso-m", "sinumerik"): 33, ("sinumerik", "iso-m"): 30}


@pytest.fixture(scope="module")
def shares():
    if not CORPUS.is_dir():
        pytest.skip("shared corpus not found")
    return {(s.source, s.target): s for s in bench_structure.structure_share(CORPUS)}


@pytest.mark.parametrize("direction", sorted(FLOORS), ids=lambda d: f"{d[0]}->{d[1]}")
def test_structural_share_holds(shares, direction):
    share = shares[direction]
    assert share.count("structural") >= FLOORS[direction], [
        (o.file, o.state, o.why) for o in share.outcomes if o.state != "structural"]


def test_whole_program_lowering_is_the_last_resort(shares):
    # a construct is lowered alone; the whole program only where one cannot be (none now: the two
    # ISO macro files that were have no toolpath of their own, their constructs are refused in place)
    assert sum(s.count("flattened") for s in shares.values()) == 0


def test_refused_in_place_is_counted_the_same_way_both_ways(shares):
    # NC412 alarm lines, per file, in either direction: the ISO programs that were refused whole for
    # one construct (a Haas G47, an unknown G41.2, a G12, PLC inputs, macro-file constructs) keep
    # their structure with the construct an alarm at its line; a template with placeholders (a
    # syntax error) stays refused
    iso = {o.file: o for o in shares[("iso-m", "sinumerik")].outcomes}
    assert iso["kiely-haas-4x3-block.nc"].state == "structural"
    assert iso["kiely-haas-4x3-block.nc"].refused_in_place == 1
    assert iso["kiely-haas-4x3-block.nc"].first_in_place == 140
    assert iso["lmhdpro-titan-tormach-ready-edited.nc"].first_in_place == 3332
    assert iso["stcline-maze-G91-incremental.nc"].state == "refused"
    sin = {o.file: o for o in shares[("sinumerik", "iso-m")].outcomes}
    assert sin["nadj-418-SH400.SPF"].state == "structural" and sin["nadj-418-SH400.SPF"].first_in_place == 27
    # a .SPF without a PROC is a subprogram file too: array elements past #999 are alarms in place
    assert sin["nadj-fb422-ML001.SPF"].state == "structural" and sin["nadj-fb422-ML001.SPF"].first_in_place == 550
