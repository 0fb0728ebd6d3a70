#!/usr/bin/env python3
"""Writes the two 64x64 PFM maps of scene.pbrt (plain Python, no dependencies):
bumps.pfm   a smooth height field 0.5 + 0.5 sin(2 pi 4 x / 64) sin(2 pi 4 y / 64) (grey RGB, linear)
ripples.pfm the tangent-space normal map of h = 0.04 sin(2 pi 2 x / 64) + 0.025 sin(2 pi 3 y / 64) in
            texels of 1/64: n = normalize(-dh/dx, -dh/dy, 1) stored as n * 0.5 + 0.5."""
import math
import struct

N = 64


def write_pfm(path, rgb_rows):  # rows top to bottom; PFM stores them bottom to top
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (N, N))
        for row in reversed(rgb_rows):
            for r, g, b in row:
                f.write(struct.pack("<fff", r, g, b))


def bumps():
    rows = []
    for y in range(N):
        row = []
        for x in range(N):
            h = 0.5 + 0.5 * math.sin(2 * math.pi * 4 * (x + 0.5) / N) * math.sin(2 * math.pi * 4 * (y + 0.5) / N)
            row.append((h, h, h))
        rows.append(row)
    return rows


def ripples():
    rows = []
    for y in range(N):
        row = []
        for x in range(N):
            s, t = (x + 0.5) / N, (y + 0.5) / N
            dhdx = 0.04 * 2 * math.pi * 2 * math.cos(2 * math.pi * 2 * s)
            dhdy = 0.025 * 2 * math.pi * 3 * math.cos(2 * math.pi * 3 * t)
            n = (-dhdx, -dhdy, 1.0)
            l = math.sqrt(sum(c * c for c in n))
            row.append(tuple(0.5 * c / l + 0.5 for c in n))
        rows.append(row)
    return rows


write_pfm("bumps.pfm", bumps())
write_pfm("ripples.pfm", ripples())
