#!/usr/bin/env python3
"""Plot the Aznalcóllar run (configs/seed002_aznalcollar.yaml, docs/aznalcollar.md): the
equivalent plastic deviatoric strain at the end of each stage (construction sequence, then the
slide), and the horizontal displacement of the dam's crest and toe against time in the slide.
Prints the failure surface at the end of the last two stages: per 4 m column, the depth below the
original ground of the foundation point with the largest plastic strain (if above 0.05).
Usage: aznalcollar_plot.py RUN_DIR --out x.png [--ground 40] [--xlim 60 300] [--vmax 0.3]"""
import argparse
import csv
import json
import os
import sys

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from terzaghi_plot import frames  # noqa: E402  ((time, path) of a run's particle frames)


def load(frame):
    with h5py.File(frame, "r") as h:
        return h["position"][:, :2], h["plastic_strain_eq"][:], h["displacement"][:, :2]


def failure_surface(x, eps, ground, x_range, width=4.0, threshold=0.05):
    """Per column of `width` m: depth below `ground` of the largest plastic strain (if above
    threshold) among the points below the ground."""
    rows = []
    for a in np.arange(x_range[0], x_range[1], width):
        sel = (x[:, 0] >= a) & (x[:, 0] < a + width) & (x[:, 1] < ground)
        if not sel.any():
            continue
        k = np.argmax(np.where(sel, eps, -1))
        if eps[k] >= threshold:
            rows.append((a + width / 2, ground - x[k, 1], eps[k]))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--out", required=True)
    ap.add_argument("--ground", type=float, default=40.0, help="original ground level y (m)")
    ap.add_argument("--xlim", type=float, nargs=2, default=[60, 300])
    ap.add_argument("--vmax", type=float, default=0.3)
    ap.add_argument("--spacing", type=float, default=1.0, help="particle spacing (m)")
    ap.add_argument("--dpi", type=int, default=80)
    a = ap.parse_args()
    with open(a.run_dir + "/summary.json") as f:
        summary = json.load(f)
    index = frames(a.run_dir)
    stages = [s for s in summary["stages"] if "end_time" in s and s["name"] != "geostatic"]
    n = len(stages)
    panel = 8.6 * 72 / (a.xlim[1] - a.xlim[0]) + 0.35  # inches: the panels keep their aspect
    fig = plt.figure(figsize=(10, panel * n + 2.8))
    grid = fig.add_gridspec(n + 1, 1, height_ratios=[panel] * n + [2.4])
    for k, st in enumerate(stages):
        ax = fig.add_subplot(grid[k])
        time, name = min(index, key=lambda f: abs(f[0] - st["end_time"]))
        x, eps, _ = load(name)
        # Squares about one particle spacing wide (1 m on 2 m cells): points per metre squared.
        size = (8.6 * 72 / (a.xlim[1] - a.xlim[0]) * a.spacing) ** 2
        sc = ax.scatter(x[:, 0], x[:, 1], c=eps, s=size, marker="s", lw=0, cmap="turbo", vmin=0,
                        vmax=a.vmax, rasterized=True)
        ax.axhline(a.ground - 14, color="w", ls=":", lw=1, zorder=3)
        ax.set_aspect("equal")
        ax.set_xlim(*a.xlim)
        ax.set_ylim(0, 72)
        ax.set_ylabel("y (m)")
        ax.text(0.01, 0.93, f"end of stage '{st['name']}' (t = {time:.1f} s)",
                transform=ax.transAxes, va="top", fontsize=8,
                bbox=dict(facecolor="white", alpha=0.8, lw=0))
        fig.colorbar(sc, ax=ax, label="plastic_strain_eq", fraction=0.02, pad=0.01)
    ax.set_xlabel("x (m); dotted: 14 m below the original ground (the observed slip surface)")
    bx = fig.add_subplot(grid[n])
    slide = stages[-1]
    for probe in ("crest", "toe"):
        try:
            with open(f"{a.run_dir}/probe_{probe}.csv") as f:
                rows = [r for r in csv.DictReader(f)]
        except FileNotFoundError:
            continue
        t = np.array([float(r["time"]) for r in rows])
        xs = np.array([float(r["position_x"]) for r in rows])
        sel = t >= slide["start_time"]
        if sel.any():
            bx.plot(t[sel] - slide["start_time"], xs[sel] - xs[sel][0],
                    label=f"{probe}: horizontal displacement (m)")
    bx.set_xlabel(f"time since the stage '{slide['name']}' began (s)")
    bx.legend(fontsize=8)
    bx.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(a.out, dpi=a.dpi)
    for st in stages[-2:]:
        time, name = min(index, key=lambda f: abs(f[0] - st["end_time"]))
        x, eps, _ = load(name)
        print(f"failure surface at the end of stage '{st['name']}' (t = {time:.1f} s): column "
              "centre x, depth below ground of the largest plastic strain, the strain")
        for xc, depth, e in failure_surface(x, eps, a.ground, a.xlim):
            print(f"  x = {xc:6.1f} m  depth {depth:5.1f} m  plastic_strain_eq {e:.3f}")

if __name__ == "__main__":
    main()
