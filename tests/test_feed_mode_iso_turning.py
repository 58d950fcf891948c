"""A converted program keeps its feed mode on and off an ISO lathe (iso-t), whose power-on feed is per
revolution (G99) where a mill, Sinumerik and Fagor start per minute: the output selects the source's
mode before its first move (G98 on iso-t, G95 on iso-m) and at every change. Found by a sweep: F300
per minute became F300 per revolution (x S mm/min) on iso-t, silently."""
from __future__ import annotations

from pathlib import Path

import pytest

import nctrans
from conftest import CORPUS
from nctrans import api

ROOT = Path(__file__).resolve().parents[1]

# One program per source dialect: the power-on feed mode (per minute, none written), then per
# revolution, then per minute again; S500 so that the wrong reading is a different feed.
SOURCES = {
    "iso-m": "%\nO1\nG21 G90\nS500 M3\nG1 X10. Z-5. F300.\nG95 G1 X12. F0.2\nG94 G1 X14. F200.\nM30\n%\n",
    "sinumerik": "G71 G90\nS500 M3\nG1 X10 Z-5 F300\nG95 G1 X12 F0.2\nG94 G1 X14 F200\nM30\n",
    "fagor": "G71 G90\nS500 M3\nG1 X10 Z-5 F300\nG95 G1 X12 F0.2\nG94 G1 X14 F200\nM30\n",
}


def _feed_modes(text: str, dialect: str) -> list:
    return [(r.feed_mode, r.feed) for r in nctrans.toolpath(text, dialect) if r.kind == "linear"]


@pytest.mark.parametrize("source", sorted(SOURCES))
def test_feed_per_minute_and_per_rev_survive_conversion_to_iso_turning(source):
    text = SOURCES[source]
    conv = nctrans.transpile(text, read=source, write="iso-t")
    assert conv.text is not None, conv.diagnostics
    assert _feed_modes(conv.text, "iso-t") == [("per_min", 300.0), ("per_rev", 0.2), ("per_min", 200.0)]
    same = api.equiv(text, conv.text, read_a=source, read_b="iso-t")
    assert same, same.message
    # the power-on mode is selected before the first move, not left to the lathe's G99
    first_move = next(i for i, line in enumerate(conv.text.splitlines()) if "G1" in line.split())
    assert "G98" in " ".join(conv.text.splitlines()[:first_move]).split()


@pytest.mark.parametrize("target", ["iso-m", "sinumerik", "fagor"])
def test_iso_turning_feed_per_rev_default_survives_conversion(target):
    # X stays 0 (diameter and radius agree there): only the feed differs between the readings
    text = "%\nO1\nG21\nS500 M3\nG1 Z-5. F0.2\nG98 G1 Z-10. F300.\nG99 G1 Z-12. F0.1\nM30\n%\n"
    conv = nctrans.transpile(text, read="iso-t", write=target)
    assert conv.text is not None, conv.diagnostics
    assert _feed_modes(conv.text, target) == [("per_rev", 0.2), ("per_min", 300.0), ("per_rev", 0.1)]
    same = api.equiv(text, conv.text, read_a="iso-t", read_b=target)
    assert same, same.message


def test_a_program_already_in_iso_turning_gets_no_extra_feed_mode():
    text = "%\nO1\nG21\nS500 M3\nG1 Z-5. F0.2\nM30\n%\n"
    conv = nctrans.transpile(text, read="iso-t", write="iso-t")
    assert "G98" not in conv.text.split() and "G99" not in conv.text.split()


# corpus programs at feed per minute that were read per revolution on iso-t before
SWEEP = [("corpus/iso-m/O2151.nc", "iso-m"), ("corpus/sinumerik/control_flow.mpf", "sinumerik"),
         ("corpus/sinumerik/lexical.mpf", "sinumerik"), ("corpus/fagor/02-parameters.nc", "fagor"),
         ("corpus/fagor/03-flow.nc", "fagor"), ("corpus/fagor/11-limits.nc", "fagor")]
SHARED_SWEEP = [("iso-mill/camotics-scorpion.nc", "iso-m"), ("iso-mill/kiely-haas-step-part.nc", "iso-m"),
                ("sinumerik/dubovikov-slot.mpf", "sinumerik")]


def _sweep() -> list:
    out = [(ROOT / p, d) for p, d in SWEEP]
    out += [(CORPUS / p, d) for p, d in SHARED_SWEEP if (CORPUS / p).is_file()]
    return out


@pytest.mark.parametrize("path,source", _sweep(), ids=lambda v: Path(v).name if isinstance(v, Path) else v)
def test_corpus_programs_keep_their_feed_mode_on_iso_turning(path, source):
    conv = nctrans.transpile(path, read=source, write="iso-t")
    assert conv.text is not None, [d.format_text() for d in conv.diagnostics]
    same = api.equiv(path, conv.text, read_a=source, read_b="iso-t")
    assert same, same.message
    modes_a = {m for m, _ in _feed_modes(path, source)}
    modes_b = {m for m, _ in _feed_modes(conv.text, "iso-t")}
    assert modes_b == modes_a
