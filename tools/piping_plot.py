#!/usr/bin/env python3
"""Plot the piping scene (configs/seed000_piping.yaml, the sheet_pile_seepage reference's
verify.csv): the exit gradient next to the pile against the head difference, from the seepage
and from the pressures, beside Harr's (measured at the same cells) and the critical gradient;
and the heave and fluidised grains against the head difference.
Usage: piping_plot.py RUN_DIR --out x.png [--critical-gradient 0.9405]"""
import argparse
import csv
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
    a = ap.parse_args()
    with open(a.run_dir + "/verify.csv") as f:
        rows = list(csv.DictReader(f))
    col = lambda k: [float(r[k]) for r in rows]
    dH = col("head_difference")
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4))
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
    bx.plot(dH, [1000 * h for h in col("heave")], "-", label="heave (mm)")
    bx.plot(dH, col("fluidised_points"), "-", label="fluidised grains downstream")
    bx.axvline(math.pi * a.depth * a.critical_gradient, color="grey", ls=":", lw=1)
    bx.set_xlabel("head difference dH (m)")
    bx.grid(alpha=0.3)
    bx.legend(fontsize=8)
    fig.suptitle("seed 000: seepage under a sheet pile (d = %g m)" % a.depth)
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)


if __name__ == "__main__":
    main()
