"""Axis-indexed position variables read the interpreter's position (Sinumerik $P_EP[Z] ...)."""
from nctrans.dialects.base import get
from nctrans.interp import interpret
from nctrans.machine import Machine


def _run(text: str, machine=None):
    program = get("sinumerik").parse(text, "t.mpf").program
    diags: list = []
    moves = [r for r in interpret(program, machine, diagnostics=diags) if r.kind in ("rapid", "linear")]
    return moves, diags


def test_programmed_end_point_reads_current_work_position():
    moves, diags = _run("G0 X1 Y2 Z30\nR1=$P_EP[Z]\nR2=$P_EP[X]\nG1 X=R1+R2 F100\nM30\n")
    assert not [d for d in diags if d.severity == "error"]
    assert moves[-1].end["X"] == 31.0


def test_machine_position_includes_the_work_offset():
    machine = Machine(offsets={"G54": {"X": 100.0}})
    moves, _ = _run("G54 G0 X5\nR1=$AA_IM[X]\nG1 X=R1 F100\nM30\n", machine)
    # $AA_IM[X] = 105 (machine), programmed as a work coordinate -> machine X 205
    assert moves[-1].end["X"] == 205.0


def test_unknown_axis_system_variable_is_flagged_not_fatal():
    moves, diags = _run("G0 X1\nR1=$AA_XYZ[X]\nG1 X=R1 F100\nM30\n")
    assert any(d.rule == "NC107" for d in diags)


def test_tool_selected_by_name_gets_the_machine_tool_with_that_name():
    from nctrans.machine import Tool
    machine = Machine(tools=[Tool(number=7, length=0.0, radius=1.0, name="DRILL")])
    program = get("sinumerik").parse('T="DRILL" M6\nG0 X1\nM30\n', "t.mpf").program
    diags: list = []
    changes = [r.tool for r in interpret(program, machine, diagnostics=diags) if r.kind == "tool_change"]
    assert changes == [7] and not diags


def test_unknown_tool_name_is_numbered_once_and_reported():
    program = get("sinumerik").parse('T="A" M6\nT="B" M6\nT="A" M6\nM30\n', "t.mpf").program
    diags: list = []
    changes = [r.tool for r in interpret(program, None, diagnostics=diags) if r.kind == "tool_change"]
    assert changes[0] == changes[2] != changes[1]
    assert [d.rule for d in diags] == ["NC107", "NC107"]


def test_system_variables_are_read_by_their_neutral_meaning_from_each_rules_table():
    from nctrans.dialects import base
    from nctrans.ir.vocabulary import SYSTEM_VARIABLES
    from nctrans.rules import load_table, system_meaning
    for d in base.dialects():
        for spelling, meaning in load_table(d.table_name).system_variables.items():
            assert meaning.split(".")[0] in SYSTEM_VARIABLES, (d.name, spelling, meaning)
    assert system_meaning(5001) == system_meaning(5041) == "axis_position_work.X"
    assert system_meaning(5023) == "axis_position_machine.Z"
    assert system_meaning("$aa_iw") == system_meaning("$P_EP") == "axis_position_work"
    assert system_meaning("$P_AXN1") == "plane_axis_1"
    assert system_meaning("$P_GG") is None and system_meaning(5100) is None


def test_iso_position_numbers_and_sinumerik_names_read_the_same_position():
    iso = get("iso-m").parse("G21 G90 G0 X3 Y4 Z5\n#1=#5001+#5042+#5023\nG1 X#1 F100\nM30\n", "t.nc").program
    diags: list = []
    moves = [r for r in interpret(iso, None, diagnostics=diags) if r.kind == "linear"]
    assert moves[-1].end["X"] == 3.0 + 4.0 + 5.0 and not diags
    moves, diags = _run("G0 X3 Y4 Z5\nR1=$AA_IW[X]+$P_EP[Y]+$AA_IM[Z]+$P_TOOLNO\nG1 X=R1 F100\nM30\n")
    assert moves[-1].end["X"] == 12.0


def test_measured_positions_are_probe_results_not_the_position():
    from nctrans.rules import system_meaning
    # seed (840D advanced programming, MEAS): $AA_MW / $AA_MM hold the measured value of the last
    # probing move; ISO #5061.. the skip position. nctrans does not model probing: unknown (NC107)
    assert system_meaning("$AA_MW") == "probe_position_work" and system_meaning("$AA_MM") == \
        "probe_position_machine"
    assert system_meaning(5061) == "probe_position_work.X"
    moves, diags = _run("G0 X3 Y4 Z5\nR1=$AA_MW[Z]\nG1 X=R1 F100\nM30\n")
    assert [d.rule for d in diags] == ["NC107"]
