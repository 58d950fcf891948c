"""The 2D backplot as SVG: one <path> per move, so the drawing can be counted and inspected.

Inside <g id="moves"> (and <g id="moves-b"> for the second program of --compare) every move is one
path element, in program order, with class "<kind> t<tool>" and data-line/data-move attributes;
rapids are dashed, feed moves solid, colours by tool. Arcs facing the view are SVG elliptical-arc
commands with equal radii (true circles), not chords. Markers, findings, difference marks, the legend,
the scale bar and the axis triad live in their own groups.
"""
from __future__ import annotations

from typing import Optional
from xml.sax.saxutils import escape

from nctrans.backplot import project as P
from nctrans.backplot.compare import Comparison
from nctrans.backplot.scene import Scene


def _n(v: float) -> str:
    s = f"{v:.2f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _pt(p) -> str:
    return f"{_n(p[0])} {_n(p[1])}"


def path_data(shp) -> str:
    if isinstance(shp, P.Arc):
        d = ["M", _pt(shp.start)]
        for radius, positive, end in shp.pieces:
            d.append(f"A{_n(radius)} {_n(radius)} 0 0 {1 if positive else 0} {_pt(end)}")
        return " ".join(d)
    pts = shp.points
    return "M" + _pt(pts[0]) + "".join(" L" + _pt(p) for p in pts[1:])


def _tool_class(t) -> str:
    return f"t{t}" if t is not None else "tnone"


def _moves_group(out: list, scene: Scene, lay: P.Layout, gid: str) -> None:
    out.append(f'<g id="{gid}" fill="none" stroke-linecap="round">')
    for m, shp in P.shapes(scene, lay):
        out.append(f'<path class="{m.kind} {_tool_class(m.tool)}" data-move="{m.index}" '
                   f'data-line="{m.line}" d="{path_data(shp)}"/>')
    out.append("</g>")


def _style(scene: Scene, b: Optional[Scene]) -> str:
    rules = ["path{stroke-width:1.2;vector-effect:non-scaling-stroke}",
             ".rapid{stroke-dasharray:5 4;stroke-opacity:.75}",
             "text{font:12px sans-serif;fill:#222}"]
    if b is None:
        for t, c in P.tool_colours(scene).items():
            rules.append(f"#moves .{_tool_class(t)}{{stroke:{c}}}")
    else:
        rules.append(f"#moves path{{stroke:{P.COMPARE_COLOURS[0]}}}")
        rules.append(f"#moves-b path{{stroke:{P.COMPARE_COLOURS[1]};stroke-width:.8}}")
    return "<style>" + "".join(rules) + "</style>"


def _markers(out: list, scene: Scene, lay: P.Layout) -> None:
    out.append('<g id="markers">')
    for mk in scene.markers:
        x, y = lay.page(mk.position)
        if mk.kind == "start":
            label = "start" + (f" T{mk.tool}" if mk.tool is not None else "")
            out.append(f'<g class="start"><circle cx="{_n(x)}" cy="{_n(y)}" r="6" fill="#0a0" stroke="#fff"/>'
                       f'<text x="{_n(x + 9)}" y="{_n(y + 16)}">{escape(label)}</text></g>')
        else:
            label = f"T{mk.tool}" if mk.tool is not None else "T?"
            out.append(f'<g class="tool-change" data-line="{mk.line}">'
                       f'<path d="M{_n(x)} {_n(y - 9)} L{_n(x + 8)} {_n(y + 5)} L{_n(x - 8)} {_n(y + 5)} Z" '
                       f'fill="#fc0" stroke="#640" style="stroke-dasharray:none"/>'
                       f'<text x="{_n(x + 10)}" y="{_n(y - 6)}">{escape(label)}</text></g>')
    out.append("</g>")


def _findings(out: list, scene: Scene, lay: P.Layout) -> None:
    if not scene.findings:
        return
    out.append('<g id="findings">')
    for f in scene.findings:
        x, y = lay.page(f.position)
        colour = P.SEVERITY_COLOURS.get(f.severity, "#8a8a8a")
        tip = f"{f.file}:{f.line}: {f.severity}[{f.code}] {f.message}"
        out.append(f'<g class="finding {escape(f.severity)}" data-line="{f.line}">'
                   f'<title>{escape(tip)}</title>'
                   f'<rect x="{_n(x - 5)}" y="{_n(y - 5)}" width="10" height="10" fill="none" '
                   f'stroke="{colour}" stroke-width="2" transform="rotate(45 {_n(x)} {_n(y)})"/></g>')
    out.append("</g>")


def _diffs(out: list, cmp: Comparison, lay: P.Layout) -> None:
    out.append('<g id="differences">')
    for k, mark in enumerate(cmp.marks):
        for side in (mark.a, mark.b):
            if side is None:
                continue
            x, y = lay.page(side.position)
            out.append(f'<g class="difference" data-line="{side.line}"><title>{escape(mark.message)}</title>'
                       f'<circle cx="{_n(x)}" cy="{_n(y)}" r="{9 if k == 0 else 6}" fill="none" '
                       f'stroke="{P.DIFF_COLOUR}" stroke-width="2"/></g>')
    out.append("</g>")


def _footer(out: list, scene: Scene, lay: P.Layout, b: Optional[Scene], cmp: Optional[Comparison]) -> None:
    y0 = lay.drawing_bottom + 20
    # scale bar: a round length about a fifth of the page
    length = P.nice_length(lay.width / 5 / lay.scale)
    px = length * lay.scale
    x0 = P.MARGIN
    out.append(f'<g id="scale-bar"><path d="M{_n(x0)} {_n(y0)} h{_n(px)} M{_n(x0)} {_n(y0 - 5)} v10 '
               f'M{_n(x0 + px)} {_n(y0 - 5)} v10" stroke="#222" stroke-width="1.5"/>'
               f'<text x="{_n(x0)}" y="{_n(y0 + 20)}">{_n(length)} mm</text></g>')
    # axis triad
    cx, cy = x0 + px + 70, y0 + 5
    colours = {"X": "#d62728", "Y": "#2ca02c", "Z": "#1f77b4"}
    out.append('<g id="axis-triad">')
    for axis, dx, dy in P.triad(lay.view):
        ex, ey = cx + dx * 30, cy + dy * 30
        out.append(f'<path d="M{_n(cx)} {_n(cy)} L{_n(ex)} {_n(ey)}" stroke="{colours[axis]}" stroke-width="2"/>'
                   f'<text x="{_n(ex + dx * 8 - 4)}" y="{_n(ey + dy * 8 + 4)}" style="fill:{colours[axis]}">'
                   f'{axis}</text>')
    out.append("</g>")
    # legend
    lx = cx + 80
    out.append('<g id="legend">')
    items: list[tuple[str, str]] = []
    if b is None:
        items = [(c, f"T{t}" if t is not None else "no tool") for t, c in P.tool_colours(scene).items()]
    else:
        items = [(P.COMPARE_COLOURS[0], f"A {scene.label}"), (P.COMPARE_COLOURS[1], f"B {b.label}")]
    for k, (colour, text) in enumerate(items[:12]):
        x = lx + (k % 6) * 120
        y = y0 - 8 + (k // 6) * 18
        out.append(f'<path d="M{_n(x)} {_n(y)} h24" stroke="{colour}" stroke-width="3"/>'
                   f'<text x="{_n(x + 30)}" y="{_n(y + 4)}">{escape(text[:40])}</text>')
    y = y0 + 36
    out.append(f'<path d="M{_n(lx)} {_n(y)} h24" stroke="#444" class="rapid" style="stroke-dasharray:5 4"/>'
               f'<text x="{_n(lx + 30)}" y="{_n(y + 4)}">rapid</text>'
               f'<path d="M{_n(lx + 90)} {_n(y)} h24" stroke="#444"/>'
               f'<text x="{_n(lx + 120)}" y="{_n(y + 4)}">feed</text>')
    out.append("</g>")
    notes = list(scene.warnings) + (list(b.warnings) if b is not None else [])
    if cmp is not None:
        notes.insert(0, "equivalent within tolerance" if cmp.equivalent
                     else f"differ: {cmp.marks[0].message}")
    if notes:
        out.append('<g id="notes">')
        for k, note in enumerate(notes[:3]):
            out.append(f'<text x="{P.MARGIN}" y="{18 + 15 * k}">{escape(note[:160])}</text>')
        out.append("</g>")


def render(scene: Scene, view: str = "top", comparison: Optional[Comparison] = None) -> str:
    """The SVG document (a string) of one scene, or of both scenes of a comparison."""
    b = comparison.b if comparison is not None else None
    scenes = [scene] + ([b] if b is not None else [])
    lay = P.layout_for(scenes, view)
    n = len(scene.moves) + (len(b.moves) if b is not None else 0)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{lay.width}" height="{lay.height}" '
           f'viewBox="0 0 {lay.width} {lay.height}" data-view="{view}" data-moves="{n}">',
           f"<title>{escape(scene.label)}: backplot, {view} view</title>",
           _style(scene, b),
           '<rect width="100%" height="100%" fill="#fff"/>']
    _moves_group(out, scene, lay, "moves")
    if b is not None:
        _moves_group(out, b, lay, "moves-b")
    _markers(out, scene, lay)
    _findings(out, scene, lay)
    if comparison is not None:
        _diffs(out, comparison, lay)
    _footer(out, scene, lay, b, comparison)
    out.append("</svg>\n")
    return "\n".join(out)

