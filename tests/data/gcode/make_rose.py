#!/usr/bin/env python3
"""Writes rose.ngc: a rose curve r = 40 cos(4 t) about X100 Y100, 3600 G1 moves with 4
decimals and N line numbers, as simple CAM post-processors write it. The corpus test
recomputes the points the same way (test_gcode_corpus.cpp)."""
import math
import sys

POINTS = 3600
out = ["%", "(rose: r = 40 cos 4t, 3600 points)", "N10 G21 G90 G17", "N20 F2400"]
n = 30


def point(k):
    t = 2 * math.pi * k / POINTS
    r = 40 * math.cos(4 * t)
    return 100 + r * math.cos(t), 100 + r * math.sin(t)


x, y = point(0)
for line in ("G0 Z2", "G0 X%.4f Y%.4f" % (x, y), "G1 Z-0.3"):
    out.append("N%d %s" % (n, line))
    n += 10
for k in range(1, POINTS + 1):
    x, y = point(k)
    out.append("N%d G1 X%.4f Y%.4f" % (n, x, y))
    n += 10
out += ["N%d G0 Z2" % n, "N%d M30" % (n + 10), "%"]
with open(sys.argv[1] if len(sys.argv) > 1 else "rose.ngc", "w") as f:
    f.write("\n".join(out) + "\n")
