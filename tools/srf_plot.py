#!/usr/bin/env python3
"""Plot a strength-reduction run (docs/strength_reduction.md): the failure mechanism (the plastic
strain and displacement of the lowest failed trial, the frame *_strength_reduction.h5) with an
optional limit-equilibrium circle, and each trial's largest displacement against its factor.
Usage: srf_plot.py RUN_DIR --out x.png [--circle XC YC R] [--title T]"""
import argparse
import glob
import json

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--out", required=True)
    ap.add_argument("--circle", type=float, nargs=3, metavar=("XC", "YC", "R"),
                    help="a slip circle to draw (e.g. Bishop's critical one, model coordinates)")
    ap.add_argument("--circle-label", default="Bishop critical circle")
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    with open(a.run_dir + "/summary.json") as f:
        s = json.load(f)
    srf = s["strength_reduction"]
    frames = sorted(glob.glob(a.run_dir + "/*_strength_reduction.h5"))
    fig, (ax, px, bx) = plt.subplots(1, 3, figsize=(17, 4.6),
                                     gridspec_kw={"width_ratios": [1.6, 1.6, 1]})
    lowest = min((t["factor"] for t in srf["trials"] if t["status"] != "static"), default=None)
    if frames:
        with h5py.File(frames[-1]) as h:
            x = h["position"][:]
            eq = h["plastic_strain_eq"][:].ravel()
            u = np.linalg.norm(h["displacement"][:], axis=1)
        for axis, value, label, cmap in [(ax, u, "displacement in the trial (m)", "viridis"),
                                         (px, eq, "equivalent plastic strain", "magma_r")]:
            sc = axis.scatter(x[:, 0], x[:, 1], c=value, s=2, cmap=cmap, vmin=0,
                              vmax=max(np.percentile(value, 99.5), 1e-9))
            fig.colorbar(sc, ax=axis, label=label, shrink=0.8)
    for axis in (ax, px):
        if a.circle:
            t = np.linspace(0, 2 * np.pi, 400)
            xc, yc, r = a.circle
            cx, cy = xc + r * np.cos(t), yc + r * np.sin(t)
            keep = (cx >= axis.get_xlim()[0]) & (cx <= axis.get_xlim()[1]) & (cy <= yc)
            axis.plot(np.where(keep, cx, np.nan), np.where(keep, cy, np.nan), "r--", lw=1.2,
                      label=a.circle_label)
            axis.legend(loc="lower left", fontsize=8)
        axis.set_aspect("equal")
        axis.set_xlabel("x (m)")
        axis.set_ylabel("y (m)")
    if lowest:
        ax.set_title(f"displacement at the end of the trial F = {lowest:.4g} (lowest failed)")
        px.set_title(f"plastic strain at the end of the trial F = {lowest:.4g}")
    for t in srf["trials"]:
        ok = t["status"] == "static"
        bx.semilogy(t["factor"], max(t["max_displacement"], 1e-6), "o" if ok else "x",
                    color="tab:green" if ok else "tab:red")
    bx.plot([], [], "o", color="tab:green", label="static")
    bx.plot([], [], "x", color="tab:red", label="failed (moved, undecided or unstable)")
    if "factor_of_safety" in srf:
        bx.axvline(srf["factor_of_safety"], color="k", lw=0.8)
        bx.set_title(f"FoS = {srf['factor_of_safety']:.4g}, bracket "
                     f"[{srf['factor_of_safety_bracket'][0]:.4g}, "
                     f"{srf['factor_of_safety_bracket'][1]:.4g}]")
    bx.set_xlabel("strength reduction factor F")
    bx.set_ylabel("largest displacement in the trial (m)")
    bx.legend()
    if a.title:
        fig.suptitle(a.title)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)


if __name__ == "__main__":
    main()
