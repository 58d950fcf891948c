"""The IR's JSON form: round trip and agreement with the published schema."""
from hypothesis import given, strategies as st

from nctrans.ir import nodes as ir
from nctrans.ir.schema import dumps, from_data, json_schema, loads, to_data

SPAN = ir.Span("t.nc", 3, 1, 3, 10)

numbers = st.floats(allow_nan=False, allow_infinity=False, width=32).map(lambda v: ir.Num(float(v)))
exprs = st.recursive(
    numbers | st.builds(ir.Var, st.just("num"), st.integers(1, 999)),
    lambda sub: st.builds(ir.Binary, st.sampled_from(["+", "-", "*", "/", "=="]), sub, sub)
    | st.builds(ir.Func, st.sampled_from(["sin", "sqrt"]), st.lists(sub, min_size=1, max_size=1)),
    max_leaves=6,
)
axis_values = st.dictionaries(st.sampled_from("XYZ"), st.builds(ir.AxisValue, exprs), min_size=1)
statements = st.one_of(
    st.builds(ir.Motion, axis_values),
    st.builds(ir.ModeChange, st.just("motion"), st.sampled_from(["rapid", "linear", "arc_cw"])),
    st.builds(ir.Feed, exprs),
    st.builds(ir.Assign, st.builds(ir.Var, st.just("num"), st.integers(1, 33)), exprs),
    st.builds(ir.Goto, st.integers(1, 9999).map(str), st.sampled_from(["forward", "any"]), exprs),
    st.just(ir.ToolChange()),
)
blocks = st.builds(ir.Block, st.just(SPAN), st.lists(statements, max_size=4),
                   st.one_of(st.none(), st.integers(1, 999).map(str)))
programs = st.builds(
    ir.Program, st.just("t.nc"), st.just("iso-m"),
    st.lists(blocks | st.builds(ir.While, st.just(SPAN), exprs, st.lists(blocks, max_size=3)), max_size=5),
)


@given(programs)
def test_json_round_trip_is_identity(program):
    assert loads(dumps(program)) == program


def test_every_node_is_tagged_and_schema_names_the_tag():
    program = ir.Program("t.nc", "iso-m", [ir.Block(SPAN, [ir.ToolChange(), ir.ResetSetPosition()])])
    data = to_data(program)
    assert data["node"] == "Program"
    assert [s["node"] for s in data["body"][0]["body"]] == ["ToolChange", "ResetSetPosition"]
    schema = json_schema()
    assert schema["$defs"]["ToolChange"]["properties"]["node"] == {"const": "ToolChange"}
    assert "node" in schema["$defs"]["Motion"]["required"]


def test_unknown_tag_is_rejected():
    import pytest
    with pytest.raises(ValueError, match="unknown IR node"):
        from_data({"node": "Teleport"})


def test_documents_validate_against_schema():
    import pytest
    jsonschema = pytest.importorskip("jsonschema")
    program = ir.Program("t.nc", "iso-m", [ir.Block(SPAN, [
        ir.ModeChange("motion", "arc_cw"),
        ir.Motion({"X": ir.AxisValue(ir.Num(10.0))}, center={"I": ir.AxisValue(ir.Num(5.0))}),
    ], number="10")])
    jsonschema.validate(to_data(program), json_schema())
    bad = to_data(program)
    bad["body"][0]["span"]["line"] = "ten"
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, json_schema())


def test_nodes_compare_and_print_as_dataclasses_do():
    import pytest
    """nodes.node shares one __repr__/__eq__ among the node classes (start-up time); the
    behaviour must stay dataclass's: field-wise equality within a class, Name(field=...) repr."""
    from nctrans.ir import nodes as n
    a = n.Motion({"X": n.AxisValue(n.Num(1.0, "1."))})
    assert a == n.Motion({"X": n.AxisValue(n.Num(1.0, "1."))})
    assert a != n.Motion({"X": n.AxisValue(n.Num(2.0, "2."))})
    assert n.Feed(n.Num(1.0, "1")) != n.SpindleSpeed(n.Num(1.0, "1"))      # other class: unequal
    assert repr(n.Num(1.0, "1.")) == "Num(value=1.0, text='1.')"
    assert repr(a).startswith("Motion(target={'X': AxisValue(value=Num(value=1.0, text='1.'), mode=None)}")
    with pytest.raises(TypeError):
        hash(a)                                                           # mutable: unhashable
    assert hash(n.Span("f", 1)) == hash(n.Span("f", 1))
