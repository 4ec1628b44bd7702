#!/usr/bin/env python3
"""Plots `rt-cli bench` JSON records as time per ray against triangle count (log x) to SVG.
Usage: rt-cli bench ... | grep '^{' > records.jsonl; bench/scaling-plot.py records.jsonl out.svg"""
import json
import math
import sys

records = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
points = sorted((r["triangles"], 1e9 / r["rays_per_s"], r["scene"]) for r in records if r["rays_per_s"] > 0)
w, h, left, right, top, bottom = 720, 420, 80, 40, 40, 60
x0 = math.floor(math.log10(min(p[0] for p in points)))
x1 = math.ceil(math.log10(max(p[0] for p in points)))
y1 = max(p[1] for p in points) * 1.2
px = lambda t: left + (math.log10(t) - x0) / (x1 - x0) * (w - left - right)
py = lambda v: h - bottom - v / y1 * (h - top - bottom)
out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">',
       f'<rect width="{w}" height="{h}" fill="white"/>',
       f'<text x="{w/2}" y="22" font-size="15" text-anchor="middle">{sys.argv[3] if len(sys.argv) > 3 else "time per ray against scene size"}</text>']
for d in range(x0, x1 + 1):
    x = px(10 ** d)
    out.append(f'<line x1="{x}" y1="{top}" x2="{x}" y2="{h-bottom}" stroke="#ddd"/><text x="{x}" y="{h-bottom+18}" text-anchor="middle">1e{d}</text>')
for k in range(0, 6):
    v = y1 * k / 5
    y = py(v)
    out.append(f'<line x1="{left}" y1="{y}" x2="{w-right}" y2="{y}" stroke="#ddd"/><text x="{left-6}" y="{y+4}" text-anchor="end">{v:.0f}</text>')
out.append(f'<rect x="{left}" y="{top}" width="{w-left-right}" height="{h-top-bottom}" fill="none" stroke="black"/>')
out.append(f'<text x="{(left+w-right)/2}" y="{h-16}" text-anchor="middle">triangles (log scale)</text>')
out.append(f'<text transform="translate(20 {(top+h-bottom)/2}) rotate(-90)" text-anchor="middle">ns per ray</text>')
out.append('<polyline points="' + " ".join(f"{px(t):.1f},{py(v):.1f}" for t, v, _ in points) + '" fill="none" stroke="#1f77b4" stroke-width="2"/>')
for t, v, name in points:
    # Labels right of points in the left half, left of them in the right half, so none leave the plot.
    right = px(t) > w / 2
    x, anchor = (px(t) - 6, "end") if right else (px(t) + 6, "start")
    out.append(f'<circle cx="{px(t):.1f}" cy="{py(v):.1f}" r="3.5" fill="#1f77b4"/><text x="{x:.1f}" y="{py(v)-6:.1f}" text-anchor="{anchor}">{name} ({t:,} tris, {v:.0f} ns)</text>')
out.append("</svg>")
open(sys.argv[2], "w").write("\n".join(out) + "\n")
