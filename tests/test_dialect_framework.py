"""The dialect framework: registration by subclassing, family bases, and the consumers (detection,
pipeline, resolver) reading what a dialect declares instead of lists of their own."""
from __future__ import annotations

import re

import pytest

from nctrans import detection as detect, pipeline
from nctrans.dialects import base
from nctrans.dialects.base import Dialect, Marker, ParseResult
from nctrans.dialects.iso_m import IsoFamily, IsoMilling
from nctrans.ir import nodes as n


def test_every_dialect_package_registers_its_class():
    assert sorted(base.names()) == ["fagor", "iso-m", "iso-t", "sinumerik"]
    assert isinstance(base.get("iso-m"), IsoMilling) and base.get("nope") is None
    with pytest.raises(KeyError, match="unknown dialect 'nope'"):
        base.get_or_raise("nope")


def test_a_family_base_without_a_name_is_not_registered_and_a_subclass_is():
    class Family(Dialect, register=False):
        pass

    base.names()                    # discover first: the snapshot must hold every dialect
    before = dict(base._REGISTRY)
    try:
        class Sub(Family):          # no name of its own: abstract, not registered
            extensions = (".x",)
        assert base._REGISTRY == before

        class Turning(IsoFamily):   # the way ISO turning extends the ISO family
            name = "test-turning"
            extensions = (".tt",)
            machine_kind = "lathe"
        t = base.get("test-turning")
        assert isinstance(t, Turning) and t.markers == IsoMilling.markers
        assert t.table_name == "test-turning"
        assert "O0012.nc" in t.subprogram_files("12") and "O0012.tt" in t.subprogram_files("12")
        assert pipeline.load_machine(None, "test-turning").kind == "lathe"
        assert pipeline.load_machine(None, "iso-m").kind == "mill"
    finally:
        base._REGISTRY.clear()
        base._REGISTRY.update(before)
    assert base.get("test-turning") is None


class Marked(Dialect, register=False):
    """A dialect known only by one marker and one comment shape."""
    name = "marked"
    extensions = (".mk",)
    markers = (Marker(4.0, 1, re.compile(r"^ZAP\b")),)
    comment_evidence = {"semicolon_line": (1.0, 2)}

    def parse(self, text, file="<stdin>"):
        return ParseResult(n.Program(file, self.name, []))


def test_detection_weighs_the_markers_and_comment_shapes_a_dialect_declares():
    with base.registered_only(Marked(), base.get("iso-m")):
        g = detect.detect("ZAP 1\n;a\n;b\n;c\n", None)
        assert g.dialect == "marked"
        assert g.content["marked"] == pytest.approx(4.0 + 2.0)     # one ZAP line (cap 1), 2 of 3 ';' lines
        assert g.first_marker["marked"] == (1, 1, "ZAP")
        assert detect.extensions("marked") == (".mk",)
        assert pipeline.all_extensions() == {".mk", *detect.extensions("iso-m")}
        # the pipeline knows only registered dialects
        with pytest.raises(pipeline.PipelineError, match="unknown dialect 'sinumerik'"):
            pipeline.get_dialect("sinumerik")


def test_resolver_tries_the_callers_dialect_file_names(tmp_path):
    (tmp_path / "L10.SPF").write_text("G0 X1\nM17\n")
    (tmp_path / "O0077.nc").write_text("O77\nG0 X1\nM99\n")
    sin = pipeline.make_resolver(str(tmp_path), "sinumerik")
    iso = pipeline.make_resolver(str(tmp_path), "iso-m")
    anyd = pipeline.make_resolver(str(tmp_path), None)
    assert sin.find_file("L10").name == "L10.SPF" and iso.find_file("L10") is None
    assert iso.find_file("77").name == "O0077.nc" and sin.find_file("77") is None
    assert anyd.find_file("L10").name == "L10.SPF" and anyd.find_file("77").name == "O0077.nc"
    assert iso.find_file("../L10.SPF") is None


def test_definition_files_and_streaming_are_declared_by_the_dialect():
    assert base.get("sinumerik").definition_files == (".def",) and not base.get("iso-m").definition_files
    assert base.get("iso-m").streams and base.get("sinumerik").streams
    assert base.get("sinumerik").parse_stream("R1=2\nG0 X=R1\n") is None      # variables: parsed whole
    assert base.get("sinumerik").parse_stream("G0 X1\n") is not None          # CAM output: streamed


def test_an_iso_family_member_reuses_the_front_end_and_emitter_with_its_own_names():
    """The way iso-t / fagor extend the family: subclasses of Lowering and IsoEmitter carrying the
    member's name (and table), one handler overridden."""
    from nctrans.dialects.iso_m.emitter import IsoEmitter
    from nctrans.dialects.iso_m.frontend import B_NONMODAL, Lowering

    class MemberLowering(Lowering):
        dialect = "test-member"

        def _m_end(self, b, rule, text):      # a member that keeps program ends verbatim
            b.out.append((B_NONMODAL, self._pass(text, "end kept")))

    class MemberEmitter(IsoEmitter):
        dialect = "test-member"
        target_text = "the member"

    class Member(IsoFamily, register=False):
        name = "test-member"
        extensions = (".mem",)

        def lowering(self):
            return MemberLowering

        def emitter(self):
            return MemberEmitter

    m = Member()
    text = "%\nO0012\nG0 X1 Y2\nG1 X3 F100\nM30\n%\n"
    parsed = m.parse(text, "p.mem")
    assert parsed.program.dialect == "test-member" and not parsed.diagnostics
    last = parsed.program.body[-1].body[0]
    assert isinstance(last, n.Passthrough) and last.dialect == "test-member" and last.text == "M30"
    assert base.get("iso-m").parse(text, "p.nc").program.body[-1].body[0].__class__ is n.ProgramEnd
    streamed = m.parse_stream("G0 X1\nG1 X2 F10\n", "s.mem")
    assert streamed.program.dialect == "test-member"
    blocks = [b for item in streamed.program.body
              for b in (item.expand() if hasattr(item, "expand") else [item])]
    assert [type(s).__name__ for b in blocks for s in b.body][-1] == "Motion"
    out = m.emit(parsed.program)
    assert "M30" in out.text and out.text.startswith("%")    # its own passthrough is written back
