#!/usr/bin/env python3
"""Plot the piping scene (configs/seed000_piping.yaml, the sheet_pile_seepage reference's
verify.csv): the exit gradient next to the pile against the head difference, from the seepage
and from the pressures, beside Harr's (measured at the same cells) and the critical gradient;
the head difference, heave, fluidised grains and pipe fraction against time; and the soil next
to the pile in the last solid frame, coloured by porosity, fluidised grains marked.
Usage: piping_plot.py RUN_DIR --out x.png [--critical-gradient 0.9405] [--pile 4.0 4.25]"""
import argparse
import csv
import glob
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--out", required=True)
    ap.add_argument("--critical-gradient", type=float, default=0.9405)
    ap.add_argument("--depth", type=float, default=1.0, help="pile embedment d (m)")
    ap.add_argument("--pile", type=float, nargs=2, default=[4.0, 4.25],
                    help="the pile's faces along x (m)")
    ap.add_argument("--surface", type=float, default=4.0, help="the soil surface (m)")
    a = ap.parse_args()
    with open(a.run_dir + "/verify.csv") as f:
        rows = list(csv.DictReader(f))
    col = lambda k: [float(r[k]) for r in rows]
    dH = col("head_difference")
    fig, (ax, bx, cx) = plt.subplots(1, 3, figsize=(16, 4.4))
    ax.plot(dH, col("exit_gradient"), ".", ms=3, label="loam, from the seepage n (w - v)/k")
    ax.plot(dH, col("exit_gradient_pressure"), ".", ms=2, alpha=0.5,
            label="loam, from the pressures")
    ax.plot(dH, col("exit_gradient_harr"), "-", lw=1.5, label="Harr (1962), same cells")
    ax.axhline(a.critical_gradient, color="k", ls="--", lw=1, label="i_c = (G_s - 1)(1 - n)")
    ax.axvline(math.pi * a.depth * a.critical_gradient, color="grey", ls=":", lw=1,
               label="dH_c = pi d i_c")
    ax.set_xlabel("head difference dH (m)")
    ax.set_ylabel("exit gradient next to the pile")
    ax.set_ylim(-0.6, 1.6)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    t = col("time")
    bx.plot(t, [1000 * h for h in col("heave")], "-", label="heave (mm)")
    bx.plot(t, col("fluidised_points"), "-", label="fluidised grains downstream")
    bx.plot(t, [100 * h for h in dH], "-", lw=1, label="dH (cm)")
    if "pipe_fraction" in rows[0]:
        bx.plot(t, [100 * p for p in col("pipe_fraction")], "-", lw=2,
                label="pipe along the pile (% of d)")
    bx.set_xlabel("time (s)")
    bx.grid(alpha=0.3)
    bx.legend(fontsize=8)
    frames = sorted(glob.glob(a.run_dir + "/solid_[0-9]*.h5"))
    if frames:
        import h5py
        import numpy as np
        with h5py.File(frames[-1], "r") as h:
            x, n, c = h["position"][:], h["porosity"][:].ravel(), h["contact"][:].ravel()
        lo, hi = a.pile[0] - 1.5 * a.depth, a.pile[1] + 2 * a.depth
        m = (x[:, 0] > lo) & (x[:, 0] < hi) & (x[:, 1] > a.surface - 2 * a.depth)
        sc = cx.scatter(x[m, 0], x[m, 1], c=n[m], s=6, cmap="viridis", vmin=0.43, vmax=0.6)
        f = m & (c == 0)
        cx.scatter(x[f, 0], x[f, 1], s=14, facecolors="none", edgecolors="r", lw=0.8,
                   label="fluidised (n >= n_max)")
        cx.add_patch(plt.Rectangle((a.pile[0], a.surface - a.depth), a.pile[1] - a.pile[0],
                                   3 * a.depth, color="0.5"))
        cx.set_xlim(lo, hi)
        cx.set_ylim(a.surface - 2 * a.depth, a.surface + 0.75 * a.depth)
        cx.set_aspect("equal")
        cx.set_title("soil at the last frame (%s)" % frames[-1].split("/")[-1], fontsize=9)
        cx.legend(fontsize=8, loc="lower right")
        fig.colorbar(sc, ax=cx, label="porosity")
    fig.suptitle("seed 000: seepage under a sheet pile (d = %g m)" % a.depth)
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)


if __name__ == "__main__":
    main()
