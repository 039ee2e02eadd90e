#!/usr/bin/env python3
"""Plot a slope-failure run (configs/seed004_slope_large_deformation.yaml, seed002_slope_*.yaml):
snapshots of the particles at given times since the failure stage's start (the last stage whose
reset: restarts the displacement), coloured by a particle field (default strain_magnitude), and the
slope_failure reference's series (largest and mean displacement, the largest speed over each
sampling interval) against time.
Usage: slope_failure_plot.py RUN_DIR --out x.png [--times 5 25 50 75 100] [--field F]
       [--vmax V] [--title T] [--xlim A B] [--dpi N]"""
import argparse
import json
import re

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def frames(run_dir):
    """(time, file) of every regular frame, from the XDMF index."""
    with open(f"{run_dir}/particles.xdmf") as f:
        text = f.read()
    out = []
    for grid in re.findall(r"<Grid Name=\"[^\"]*\" GridType=\"Uniform\">(.*?)</Grid>", text, re.S):
        t = re.search(r'Time Value="([^"]+)"', grid)
        h5 = re.search(r"([\w.]+\.h5):/position", grid)
        if t and h5 and "failed" not in h5.group(1):
            out.append((float(t.group(1)), h5.group(1)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--out", required=True)
    ap.add_argument("--times", type=float, nargs="+", default=[5, 25, 50, 75, 100],
                    help="snapshot times (s) since the last displacement reset")
    ap.add_argument("--field", default="strain_magnitude")
    ap.add_argument("--vmax", type=float, default=1.0, help="colour scale's top")
    ap.add_argument("--title", default="")
    ap.add_argument("--xlim", type=float, nargs=2)
    ap.add_argument("--dpi", type=int, default=80)
    a = ap.parse_args()
    with open(a.run_dir + "/summary.json") as f:
        summary = json.load(f)
    # The measurement's start: the last stage that resets the displacement (else t = 0).
    t0 = 0.0
    for cfg, rec in zip(summary["config"].get("stages", []), summary.get("stages", [])):
        if "displacement" in cfg.get("reset", []) and "start_time" in rec:
            t0 = rec["start_time"]
    index = frames(a.run_dir)
    n = len(a.times)
    with h5py.File(f"{a.run_dir}/{index[0][1]}", "r") as h:
        x0 = h["position"][:, :2]
    xr = a.xlim if a.xlim else (x0[:, 0].min() - 0.5, x0[:, 0].max() + 0.5)
    panel = 9.5 * (x0[:, 1].max() - x0[:, 1].min() + 1) / (xr[1] - xr[0]) + 0.3
    fig = plt.figure(figsize=(11, panel * n + 3))
    grid = fig.add_gridspec(n + 1, 1, height_ratios=[panel] * n + [2.6])
    for k, t in enumerate(a.times):
        ax = fig.add_subplot(grid[k])
        time, name = min(index, key=lambda f: abs(f[0] - t0 - t))
        with h5py.File(f"{a.run_dir}/{name}", "r") as h:
            x = h["position"][:, :2]
            c = h[a.field][:] if a.field in h else np.zeros(len(x))
        sc = ax.scatter(x[:, 0], x[:, 1], c=c, s=4, marker="s", lw=0, cmap="turbo", vmin=0, vmax=a.vmax,
                        rasterized=True)
        ax.set_aspect("equal")
        ax.set_xlim(*xr)
        ax.set_ylabel("y (m)")
        ax.text(0.01, 0.95, f"t = {time - t0:.1f} s", transform=ax.transAxes, va="top",
                bbox=dict(facecolor="white", alpha=0.8, lw=0))
        fig.colorbar(sc, ax=ax, label=a.field, fraction=0.02, pad=0.01)
    ax.set_xlabel("x (m)")
    v = summary["verify"]
    s = v.get("series", {})
    bx = fig.add_subplot(grid[n])
    if s:
        bx.plot(s["time_since_reset"], s["max_displacement"], label="largest displacement (m)")
        bx.plot(s["time_since_reset"], s["mean_displacement"], label="mean displacement (m)")
        bx.plot(s["time_since_reset"], s["interval_speed"],
                label="largest speed over each interval (m/s)", lw=0.8)
        bx.set_yscale("symlog", linthresh=1e-3)
    rest = v.get("time_to_rest")
    if rest is not None:
        bx.axvline(rest, color="k", ls="--", lw=1, label=f"failed mass at rest: {rest:.0f} s")
    if v.get("paper_time_to_rest"):
        bx.axvline(v["paper_time_to_rest"], color="grey", ls=":", lw=1.5,
                   label=f"paper: at rest after about {v['paper_time_to_rest']:.0f} s")
    bx.set_xlabel("time since the failure stage's start (s)")
    bx.legend(fontsize=8, loc="center right")
    bx.grid(alpha=0.3)
    if a.title:
        fig.suptitle(a.title)
    fig.tight_layout()
    fig.savefig(a.out, dpi=a.dpi)


if __name__ == "__main__":
    main()
