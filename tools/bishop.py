#!/usr/bin/env python3
"""Limit-equilibrium factor of safety of a simple slope by Bishop's simplified method over
circular slip surfaces (the independent check of loam's strength-reduction factor).

The slope: a crest at height H for x <= 0, a face at angle beta down to the toe at
(H / tan beta, 0), a level ground at y = 0 beyond, and an optional firm base at depth D below
the toe (no circle goes below y = -D). Soil: unit weight gamma, cohesion c, friction angle phi,
and a pore pressure u = r_u gamma h on the base of a slice of height h (Bishop & Morgenstern's
pore-pressure ratio; 0: dry or drained with the water table below the slip).

Bishop (1955), the simplified method: moment equilibrium about the circle's centre with the
interslice shear forces neglected, for n slices of width b, weight W, base angle alpha
(sin alpha = (x_c - x) / R for a slope falling towards +x),
    F = sum[(c b + (W - u b) tan phi) / m_alpha] / sum W sin alpha,
    m_alpha = cos alpha + sin alpha tan phi / F,
solved by fixed-point iteration. For phi = 0 it is the exact moment balance of the circle
(Fellenius), so its minimum over circles is Taylor's (1937) stability number
N_s = c / (F gamma H): 0.261 for a vertical face, 0.191 at 60 deg (toe circles). For c = 0 the
shallowest circles approach the infinite slope, F = tan phi / tan beta.

The search: circle centres on a grid above the slope, each with the radii through the toe and,
where a firm base allows it, deeper ones down to it; the smallest F is reported with its circle.
Usage:
  bishop.py --height H --angle BETA --gamma G --c C --phi PHI [--ru RU] [--depth D] [--json]
"""
import argparse
import json
import math

import numpy as np


def ground(x, height, angle):
    """Ground surface y(x): crest at `height` for x <= 0, the face, level ground at 0."""
    toe = height / math.tan(math.radians(angle))
    return np.where(x <= 0, height, np.where(x >= toe, 0.0, height * (1 - x / toe)))


def bishop_factor(xc, yc, r, soil, slices=200):
    """Bishop's simplified F of the circle (xc, yc, r), or None if it cuts no sliding mass."""
    height, angle, gamma, c, phi, ru = soil
    # The circle meets the ground where its lower arc crosses y(x); find the span by sampling.
    x = np.linspace(xc - r, xc + r, 4 * slices + 1)
    yb = yc - np.sqrt(np.maximum(r * r - (x - xc) ** 2, 0.0))
    inside = ground(x, height, angle) - yb > 1e-9
    if inside.sum() < 4:
        return None
    idx = np.nonzero(inside)[0]
    # A slip surface enters and leaves through the ground surface: the circle's extreme points
    # lie above the ground, and the sliding mass is one piece.
    if inside[0] or inside[-1] or idx[-1] - idx[0] + 1 != len(idx):
        return None
    x0, x1 = x[idx[0]], x[idx[-1]]
    edges = np.linspace(x0, x1, slices + 1)
    xm = 0.5 * (edges[:-1] + edges[1:])
    b = edges[1:] - edges[:-1]
    base = yc - np.sqrt(np.maximum(r * r - (xm - xc) ** 2, 0.0))
    h = np.maximum(ground(xm, height, angle) - base, 0.0)
    w = gamma * h * b
    sin_a = (xc - xm) / r
    cos_a = np.sqrt(np.maximum(1 - sin_a ** 2, 0.0))
    drive = np.sum(w * sin_a)
    if drive <= 1e-12 * max(np.sum(w), 1e-300):
        return None
    tan_phi = math.tan(math.radians(phi))
    u = ru * gamma * h
    # b is the slice's horizontal width, so its base is b / cos(alpha) long; Bishop's m_alpha
    # carries the cos.
    resist_num = c * b + np.maximum(w - u * b, 0.0) * tan_phi
    f = 1.0
    for _ in range(200):
        m = cos_a + sin_a * tan_phi / f
        if np.any(m <= 1e-6):
            return None  # the classical m_alpha breakdown near the crest: skip the circle
        f_new = np.sum(resist_num / m) / drive
        if abs(f_new - f) < 1e-10 * f:
            return f_new
        f = f_new
    return f


def search(soil, depth=None, grid=40):
    """The smallest F over circle centres above the slope and radii through the toe or deeper."""
    height, angle = soil[0], soil[1]
    toe = height / math.tan(math.radians(angle))
    best = (math.inf, None)
    xs = np.linspace(-1.5 * height, toe + 0.5 * height, grid)
    ys = np.linspace(0.2 * height, 3.0 * height, grid)
    for xc in xs:
        for yc in ys:
            r_toe = math.hypot(xc - toe, yc)
            radii = [r_toe]
            if depth is not None:  # deeper circles, down to the firm base
                r_max = yc + depth
                radii += list(np.linspace(r_toe, max(r_toe, r_max), 6)[1:])
            for r in radii:
                if depth is not None and yc - r < -depth - 1e-9:
                    continue
                f = bishop_factor(xc, yc, r, soil)
                if f is not None and f < best[0]:
                    best = (f, (xc, yc, r))
    # Refine around the best centre.
    f0, circ = best
    if circ is None:
        return best
    span = (xs[1] - xs[0], ys[1] - ys[0])
    for _ in range(3):
        xc0, yc0, r0 = circ
        for xc in np.linspace(xc0 - span[0], xc0 + span[0], 11):
            for yc in np.linspace(yc0 - span[1], yc0 + span[1], 11):
                for dr in np.linspace(-0.1 * height, 0.1 * height, 11):
                    r = r0 + dr
                    if r <= 0 or (depth is not None and yc - r < -depth - 1e-9):
                        continue
                    f = bishop_factor(xc, yc, r, soil)
                    if f is not None and f < best[0]:
                        best = (f, (xc, yc, r))
        circ = best[1]
        span = (span[0] / 5, span[1] / 5)
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--height", type=float, required=True, help="slope height H (m)")
    ap.add_argument("--angle", type=float, required=True, help="face angle beta (deg)")
    ap.add_argument("--gamma", type=float, required=True, help="unit weight (N/m^3)")
    ap.add_argument("--c", type=float, required=True, help="cohesion (Pa)")
    ap.add_argument("--phi", type=float, required=True, help="friction angle (deg)")
    ap.add_argument("--ru", type=float, default=0.0, help="pore-pressure ratio r_u")
    ap.add_argument("--depth", type=float, default=None,
                    help="depth of a firm base below the toe (m; default: toe circles only)")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    a = ap.parse_args()
    if a.height <= 0 or not 0 < a.angle <= 90 or a.gamma <= 0 or a.c < 0 or a.phi < 0:
        ap.error("need height > 0, 0 < angle <= 90, gamma > 0, c >= 0, phi >= 0")
    if a.c == 0 and a.phi == 0:
        ap.error("c = 0 and phi = 0: no strength")
    soil = (a.height, a.angle, a.gamma, a.c, a.phi, a.ru)
    f, circ = search(soil, a.depth)
    out = {"factor_of_safety": f, "centre": [circ[0], circ[1]] if circ else None,
           "radius": circ[2] if circ else None,
           "taylor_stability_number": a.c / (f * a.gamma * a.height) if a.c > 0 else None}
    if a.json:
        print(json.dumps(out))
    else:
        print("Bishop simplified F = %.4f, circle centre (%.3f, %.3f) m, radius %.3f m"
              % (f, circ[0], circ[1], circ[2]))


if __name__ == "__main__":
    main()
