"""The 2D backplot as PNG: the SVG's picture (same layout and shapes), drawn with Pillow.

Pillow rather than rasterising the SVG: it is one self-contained wheel (no system cairo, no
browser at run time), and drawing the shapes directly takes well under a second for 100k moves.
Pillow draws without anti-aliasing, so the picture is drawn at twice the size and reduced with a
Lanczos filter. Arcs are tessellated to a quarter of a (final) pixel; rapids are dashed by walking
their length. The PNG carries tEXt entries nctrans:moves (moves drawn) and nctrans:view.
"""
from __future__ import annotations

import io
import math
from typing import Optional

from nctrans.backplot import project as P
from nctrans.backplot.compare import Comparison
from nctrans.backplot.scene import Scene

SUPERSAMPLE = 2
DASH, GAP = 5.0, 4.0          # page pixels, as the SVG's stroke-dasharray


def _rgb(hex_colour: str, alpha: float = 1.0) -> tuple[int, int, int]:
    r, g, b = int(hex_colour[1:3], 16), int(hex_colour[3:5], 16), int(hex_colour[5:7], 16)
    if alpha < 1.0:        # blend towards the white background
        r, g, b = (round(c * alpha + 255 * (1 - alpha)) for c in (r, g, b))
    return (r, g, b)


def _dashes(points: list[tuple[float, float]], dash: float, gap: float):
    """Split a polyline into dash polylines (pattern restarts on each move, like SVG)."""
    on, left = True, dash
    cur = [points[0]]
    for (x0, y0), (x1, y1) in zip(points, points[1:]):
        seg = math.hypot(x1 - x0, y1 - y0)
        pos = 0.0
        while seg - pos > left:
            pos += left
            f = pos / seg
            p = (x0 + (x1 - x0) * f, y0 + (y1 - y0) * f)
            if on:
                cur.append(p)
                yield cur
            cur = [p]
            on = not on
            left = dash if on else gap
        left -= seg - pos
        if on:
            cur.append((x1, y1))
        else:
            cur = [(x1, y1)]
    if on and len(cur) > 1:
        yield cur


def _page_points(shp) -> list[tuple[float, float]]:
    if isinstance(shp, P.Arc):
        return P.arc_tessellation(shp, 0.25)
    return shp.points


def render(scene: Scene, view: str = "top", comparison: Optional[Comparison] = None) -> bytes:
    from PIL import Image, ImageDraw, ImageFont, PngImagePlugin
    b = comparison.b if comparison is not None else None
    scenes = [scene] + ([b] if b is not None else [])
    lay = P.layout_for(scenes, view)
    k = SUPERSAMPLE
    img = Image.new("RGB", (lay.width * k, lay.height * k), "white")
    draw = ImageDraw.Draw(img)
    drawn = 0
    for n, sc in enumerate(scenes):
        colours = P.tool_colours(sc)
        width = k if n == 0 else max(1, k - 1)
        for m, shp in P.shapes(sc, lay):
            colour = P.COMPARE_COLOURS[n] if b is not None else colours.get(m.tool, P.PALETTE[0])
            pts = [(x * k, y * k) for x, y in _page_points(shp)]
            if m.kind == "rapid":
                fill = _rgb(colour, 0.75)
                for dash in _dashes(pts, DASH * k, GAP * k):
                    draw.line(dash, fill=fill, width=width)
            else:
                draw.line(pts, fill=_rgb(colour), width=width, joint="curve")
            drawn += 1
    font = ImageFont.load_default(size=12 * k)
    for mk in scene.markers:
        x, y = (c * k for c in lay.page(mk.position))
        if mk.kind == "start":
            draw.ellipse((x - 6 * k, y - 6 * k, x + 6 * k, y + 6 * k), fill=(0, 170, 0), outline="white")
            draw.text((x + 9 * k, y + 4 * k), "start" + (f" T{mk.tool}" if mk.tool is not None else ""),
                      fill=(34, 34, 34), font=font)
        else:
            draw.polygon([(x, y - 9 * k), (x + 8 * k, y + 5 * k), (x - 8 * k, y + 5 * k)],
                         fill=(255, 204, 0), outline=(102, 68, 0))
            draw.text((x + 10 * k, y - 18 * k), f"T{mk.tool}" if mk.tool is not None else "T?",
                      fill=(34, 34, 34), font=font)
    for f in scene.findings:
        x, y = (c * k for c in lay.page(f.position))
        r = 7 * k
        draw.polygon([(x, y - r), (x + r, y), (x, y + r), (x - r, y)],
                     outline=_rgb(P.SEVERITY_COLOURS.get(f.severity, "#8a8a8a")), width=2 * k)
    if comparison is not None:
        for i, mark in enumerate(comparison.marks):
            for side in (mark.a, mark.b):
                if side is not None:
                    x, y = (c * k for c in lay.page(side.position))
                    r = (9 if i == 0 else 6) * k
                    draw.ellipse((x - r, y - r, x + r, y + r), outline=_rgb(P.DIFF_COLOUR), width=2 * k)
    _footer(draw, font, scene, b, comparison, lay, k)
    img = img.resize((lay.width, lay.height), Image.Resampling.LANCZOS)
    info = PngImagePlugin.PngInfo()
    info.add_text("nctrans:moves", str(drawn))
    info.add_text("nctrans:view", view)
    buf = io.BytesIO()
    img.save(buf, format="PNG", pnginfo=info, optimize=False)
    return buf.getvalue()


def _footer(draw, font, scene: Scene, b: Optional[Scene], cmp: Optional[Comparison], lay: P.Layout,
            k: int) -> None:
    ink = (34, 34, 34)
    y0 = (lay.drawing_bottom + 20) * k
    length = P.nice_length(lay.width / 5 / lay.scale)
    px = length * lay.scale * k
    x0 = P.MARGIN * k
    draw.line([(x0, y0), (x0 + px, y0)], fill=ink, width=2 * k)
    for x in (x0, x0 + px):
        draw.line([(x, y0 - 5 * k), (x, y0 + 5 * k)], fill=ink, width=2 * k)
    draw.text((x0, y0 + 9 * k), f"{length:g} mm", fill=ink, font=font)
    cx, cy = x0 + px + 70 * k, y0 + 5 * k
    axis_colours = {"X": "#d62728", "Y": "#2ca02c", "Z": "#1f77b4"}
    for axis, dx, dy in P.triad(lay.view):
        ex, ey = cx + dx * 30 * k, cy + dy * 30 * k
        draw.line([(cx, cy), (ex, ey)], fill=_rgb(axis_colours[axis]), width=2 * k)
        draw.text((ex + dx * 8 * k - 4 * k, ey + dy * 8 * k - 8 * k), axis, fill=_rgb(axis_colours[axis]), font=font)
    lx = cx + 80 * k
    if b is None:
        items = [(c, f"T{t}" if t is not None else "no tool") for t, c in P.tool_colours(scene).items()]
    else:
        items = [(P.COMPARE_COLOURS[0], f"A {scene.label}"), (P.COMPARE_COLOURS[1], f"B {b.label}")]
    for i, (colour, text) in enumerate(items[:12]):
        x = lx + (i % 6) * 120 * k
        y = y0 - 8 * k + (i // 6) * 18 * k
        draw.line([(x, y), (x + 24 * k, y)], fill=_rgb(colour), width=3 * k)
        draw.text((x + 30 * k, y - 8 * k), text[:40], fill=ink, font=font)
    notes = list(scene.warnings) + (list(b.warnings) if b is not None else [])
    if cmp is not None:
        notes.insert(0, "equivalent within tolerance" if cmp.equivalent else f"differ: {cmp.marks[0].message}")
    for i, note in enumerate(notes[:3]):
        draw.text((P.MARGIN * k, (6 + 15 * i) * k), note[:160], fill=ink, font=font)
