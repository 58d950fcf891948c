"""The interactive viewer: one self-contained HTML file (no network), built from backplot/ assets.

The page is backplot/viewer.html with viewer.css and viewer.js inlined and the scene as JSON. The
geometry travels as base64 typed arrays (float32 vertices relative to the part's centre, so float32
keeps micrometres; per-move kind, tool, line and file), which the page hands to WebGL as they are:
a 100k-move program loads in a fraction of a second and stays interactive.
`render` returns the page as a string (the Python API's _repr_html_ can use it).
"""
from __future__ import annotations

import base64
import json
import re
from array import array
from html import escape
from typing import Optional

from nctrans.backplot import assets
from nctrans.backplot import project as P
from nctrans.backplot.compare import Comparison
from nctrans.backplot.scene import Scene

KIND_CODES = {"rapid": 0, "linear": 1, "arc": 2}
NO_TOOL = -1


def _b64(arr: array) -> str:
    if arr.itemsize > 1 and array("H", [1]).tobytes()[0] != 1:     # the page reads little-endian
        arr = array(arr.typecode, arr)
        arr.byteswap()
    return base64.b64encode(arr.tobytes()).decode("ascii")


def _rel(p, origin) -> list[float]:
    return [round(p[0] - origin[0], 6), round(p[1] - origin[1], 6), round(p[2] - origin[2], 6)]


def _program(scene: Scene, origin, tol: float) -> dict:
    pts, mstart = array("f"), array("I")
    kind, tool, line, file = array("B"), array("i"), array("I"), array("H")
    files = scene.files() or [scene.label]
    file_index = {f: i for i, f in enumerate(files)}
    ox, oy, oz = origin
    for m in scene.moves:
        mstart.append(len(pts) // 3)
        seq = [m.start] + (P.arc_polyline(m, tol) if m.kind == "arc" else [m.end])
        for p in seq:
            pts.extend((p[0] - ox, p[1] - oy, p[2] - oz))
        kind.append(KIND_CODES[m.kind])
        tool.append(m.tool if m.tool is not None else NO_TOOL)
        line.append(max(m.line, 0))
        file.append(file_index.get(m.file, 0))
    mstart.append(len(pts) // 3)
    colours = P.tool_colours(scene)
    return {"label": scene.label, "files": files,
            "tools": [t if t is not None else NO_TOOL for t in colours],
            "colours": list(colours.values()),
            "pts": _b64(pts), "mstart": _b64(mstart), "kind": _b64(kind), "tool": _b64(tool),
            "line": _b64(line), "file": _b64(file)}


def page_data(scene: Scene, sources: dict[str, str], view: str = "top",
              comparison: Optional[Comparison] = None) -> dict:
    """The JSON the viewer reads (see backplot/viewer.js)."""
    scenes = [scene] + ([comparison.b] if comparison is not None else [])
    lo = [min(s.bounds()[0][k] for s in scenes if not s.empty) if any(not s.empty for s in scenes) else 0.0
          for k in range(3)]
    hi = [max(s.bounds()[1][k] for s in scenes if not s.empty) if any(not s.empty for s in scenes) else 0.0
          for k in range(3)]
    origin = [(a + b) / 2 for a, b in zip(lo, hi)]
    diag = max(s.diagonal() for s in scenes)
    tol = max(0.001, diag * 2e-5)
    data = {
        "title": scene.label + (f"  vs  {comparison.b.label}" if comparison is not None else ""),
        "view": view,
        "origin": origin,
        "bounds": [_rel(lo, origin), _rel(hi, origin)],
        "programs": [_program(s, origin, tol) for s in scenes],
        "sources": {name: text for name, text in sources.items()},
        "markers": [{"kind": mk.kind, "p": _rel(mk.position, origin), "move": mk.move_index,
                     "file": mk.file, "line": mk.line, "tool": mk.tool} for mk in scene.markers],
        "findings": [{"file": f.file, "line": f.line, "severity": f.severity, "code": f.code,
                      "message": f.message, "p": _rel(f.position, origin)} for f in scene.findings],
        "warnings": [w for s in scenes for w in s.warnings],
    }
    if comparison is not None:
        data["compare"] = {"colours": list(P.COMPARE_COLOURS), "truncated": comparison.truncated}
        data["differences"] = [
            {"message": d.message,
             "a": None if d.a is None else {"file": d.a.file, "line": d.a.line, "move": d.a.move_index,
                                            "p": _rel(d.a.position, origin)},
             "b": None if d.b is None else {"file": d.b.file, "line": d.b.line, "move": d.b.move_index,
                                            "p": _rel(d.b.position, origin)}}
            for d in comparison.marks]
    return data


_SLOT = re.compile(r"\{\{(TITLE|CSS|JS|DATA)\}\}")


def render(scene: Scene, sources: dict[str, str], view: str = "top",
           comparison: Optional[Comparison] = None) -> str:
    """The viewer page as one string."""
    data = json.dumps(page_data(scene, sources, view, comparison), separators=(",", ":"), allow_nan=False)
    values = {
        "TITLE": escape(f"{scene.label} - nctrans backplot"),
        "CSS": assets.read_text("viewer.css"),
        "JS": assets.read_text("viewer.js").replace("</script", "<\\/script"),
        # inside <script type="application/json"> only "</" could end the element early
        "DATA": data.replace("</", "<\\/"),
    }
    return _SLOT.sub(lambda m: values[m.group(1)], assets.read_text("viewer.html"))
