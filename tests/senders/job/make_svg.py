"""Authors job.svg, the drawing the senders' laser job is generated from
(see generate.sh): a 50 x 35 mm frame, three circles, the text "LA" as
glyph outlines (DejaVu Sans Bold, converted to paths with fontTools, as a
vector editor's "object to path" does) and a raster of short dashes whose
grey level (laser power) varies by row. Units: mm, SVG y down.
Usage: make_svg.py FONT.ttf > job.svg"""
import sys

from fontTools.pens.boundsPen import BoundsPen
from fontTools.pens.svgPathPen import SVGPathPen
from fontTools.pens.transformPen import TransformPen
from fontTools.ttLib import TTFont

W, H = 50.0, 35.0
HAIR = 'fill="none" stroke-width="0.1"'


def path(d, grey="#000000"):
    return f'  <path {HAIR} stroke="{grey}" d="{d}" />'


def circle(cx, cy, r):
    # Two half arcs from the rightmost point.
    return (f"M {cx + r:g},{cy:g} A {r:g},{r:g} 0 0 1 {cx - r:g},{cy:g} "
            f"A {r:g},{r:g} 0 0 1 {cx + r:g},{cy:g} Z")


def text_outline(font_path, text, x, baseline, cap_mm):
    font = TTFont(font_path)
    glyphs = font.getGlyphSet()
    cmap = font.getBestCmap()
    bounds = BoundsPen(glyphs)
    glyphs[cmap[ord("L")]].draw(bounds)
    scale = cap_mm / bounds.bounds[3]  # cap height from the L
    pen = SVGPathPen(glyphs)
    for ch in text:
        name = cmap[ord(ch)]
        # Font units, y up -> mm, y down, origin at (x, baseline).
        glyphs[name].draw(TransformPen(pen, (scale, 0, 0, -scale, x, baseline)))
        x += glyphs[name].width * scale
    return pen.getCommands()


def main():
    out = [
        '<?xml version="1.0" encoding="UTF-8" standalone="no"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{W:g}mm" height="{H:g}mm" '
        f'viewBox="0 0 {W:g} {H:g}">',
        path(f"M 0,0 H {W:g} V {H:g} H 0 Z"),
        path(circle(10, 8.75, 6.25)),
        path(circle(25, 8.75, 5)),
        path(circle(40, 8.75, 3.75)),
        path(text_outline(sys.argv[1], "LA", 5, 30, 10)),
    ]
    for row in range(5):
        y = 31.5 - 2 * row
        grey = ["#000000", "#303030", "#606060", "#909090", "#b0b0b0"][row]
        dashes = " ".join(f"M {30 + 3 * k:g},{y:g} h 1.8" for k in range(6))
        out.append(path(dashes, grey))
    out.append("</svg>")
    print("\n".join(out))


main()
