"""Backplots: the toolpath drawn as SVG, PNG, GLB or an interactive HTML viewer.

`build_scene` reads the toolpath stream once (nctrans.backplot.scene); each format has one renderer
module reading that scene. `render` picks the renderer by output format and returns the file's bytes.
"""
from __future__ import annotations

from pathlib import Path
from typing import Optional

from nctrans.backplot.scene import Finding, Scene, build_scene

FORMATS = {".svg": "svg", ".png": "png", ".glb": "glb", ".html": "html", ".htm": "html"}
VIEW_NAMES = ("top", "front", "side", "iso")



class BackplotError(Exception):
    """Something the plot needs that cannot be had (a machine mesh that does not load): exit 2."""


__all__ = ["BackplotError", "FORMATS", "VIEW_NAMES", "Finding", "Scene", "build_scene", "format_for",
           "left_out_diagnostics", "render"]


def left_out_diagnostics(scene: Scene) -> list:
    """NC011 at the first move a scene leaves out (limits.MAX_PLOTTED_MOVES), or nothing."""
    if not scene.left_out:
        return []
    from nctrans.diagnostics import Diagnostic
    r = scene.first_left_out
    return [Diagnostic("NC011", "warning", f"the backplot draws the first {len(scene.moves):,} moves; "
                       f"this one and {scene.left_out - 1:,} more are not drawn (NCTRANS_MAX_PLOTTED_MOVES)",
                       r.file, r.line, 1)]


def format_for(path: str | Path) -> Optional[str]:
    """The output format named by a file ending (case-insensitive), or None."""
    return FORMATS.get(Path(path).suffix.lower())


def render(fmt: str, scene: Scene, *, view: str = "top", comparison=None, machine=None,
           sources: Optional[dict[str, str]] = None) -> bytes:
    """The output file's content. sources: file label -> program text (the HTML viewer shows it)."""
    if fmt == "svg":
        from nctrans.backplot import svg
        return svg.render(scene, view, comparison).encode("utf-8")
    if fmt == "png":
        from nctrans.backplot import png
        return png.render(scene, view, comparison)
    if fmt == "glb":
        from nctrans.backplot import glb
        return glb.render(scene, machine, comparison)
    if fmt == "html":
        from nctrans.backplot import html
        return html.render(scene, sources or {}, view=view, comparison=comparison).encode("utf-8")
    raise ValueError(f"unknown backplot format {fmt!r}")
