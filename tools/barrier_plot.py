#!/usr/bin/python3
"""Impact of a granular flow on a rigid barrier (configs/granular_barrier_2d.yaml,
docs/contact.md): the barrier's reaction per metre over time against the hydrodynamic
estimate rho v^2 h of the flow that arrives (Hungr et al. 1984), v the mean x velocity and h
the height of the sand in a window just upstream of the barrier, from each frame; with three
snapshots of the particles coloured by speed.
Usage: barrier_plot.py RUN_DIR [--window X0 X1] [--density RHO] [--out F]"""
import argparse
import csv
import os
import sys

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from terzaghi_plot import frames  # noqa: E402  ((time, path) of a run's particle frames)


def arriving_flow(path, x0, x1, barrier_first_id):
    """Mean x velocity and height of the sand with x in [x0, x1] in one frame."""
    with h5py.File(path, "r") as f:
        ids = f["id"][:]
        x = f["position"][:]
        v = f["velocity"][:]
    sand = (ids < barrier_first_id) & (x[:, 0] >= x0) & (x[:, 0] <= x1)
    if not sand.any():
        return 0.0, 0.0
    return float(v[sand, 0].mean()), float(x[sand, 1].max())


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("run_dir")
    ap.add_argument("--window", type=float, nargs=2, default=[0.42, 0.5],
                    help="x range upstream of the barrier where v and h are taken (m)")
    ap.add_argument("--density", type=float, default=1800.0, help="the sand's density (kg/m3)")
    ap.add_argument("--barrier", default="barrier", help="the barrier's reaction name")
    ap.add_argument("--average", type=float, default=0.005,
                    help="window of the force's moving average (s): a rigid wall stops the "
                    "front's nodal momentum within a step, so single steps spike")
    ap.add_argument("--out", default="granular_barrier.png")
    a = ap.parse_args()
    rows = list(csv.DictReader(open(a.run_dir + "/history.csv")))
    t = np.array([float(r["time"]) for r in rows])
    force = np.array([float(r["reaction_" + a.barrier + "_x"]) for r in rows])
    runs = frames(a.run_dir)
    with h5py.File(runs[0][1], "r") as f:
        # the barrier is the last body: its particles have the largest ids
        x = f["position"][:]
        ids = f["id"][:]
        first = int(ids[x[:, 0] >= a.window[1]].min())
    est_t, est = [], []
    for time, path in runs:
        v, h = arriving_flow(path, a.window[0], a.window[1], first)
        est_t.append(time)
        est.append(a.density * max(v, 0.0) ** 2 * h)
    fig = plt.figure(figsize=(10, 6.5))
    ax = fig.add_subplot(2, 1, 1)
    steps = max(1, int(round(a.average / max(np.median(np.diff(t)), 1e-12))))
    mean = np.convolve(-force, np.ones(steps) / steps, mode="same")
    ax.plot(t, -force, lw=0.5, color="0.75", label="barrier's reaction, each step")
    ax.plot(t, mean, lw=1.2, label="its mean over %.3f s" % a.average)
    ax.plot(est_t, est, "o-", ms=3, label=r"$\rho v^2 h$ of the arriving flow")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("force per metre (N/m)")
    ax.legend()
    ax.grid(alpha=0.3)
    picks = [runs[len(runs) // 4], runs[len(runs) // 2], runs[-1]]
    for k, (time, path) in enumerate(picks):
        with h5py.File(path, "r") as f:
            x = f["position"][:]
            speed = np.linalg.norm(f["velocity"][:], axis=1)
        s = fig.add_subplot(2, 3, 4 + k)
        s.scatter(x[:, 0], x[:, 1], c=speed, s=0.4, cmap="viridis", vmin=0, vmax=2)
        s.set_aspect("equal")
        s.set_title("t = %.2f s" % time, fontsize=9)
        s.set_xlim(0, 0.8)
        s.set_ylim(0, 0.42)
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)
    print("peak force %.1f N/m at %.3f s (mean over %.3f s: %.1f N/m at %.3f s); largest "
          "rho v^2 h %.1f N/m at %.3f s; last %.1f N/m; wrote %s" % (
              -force.min(), t[force.argmin()], a.average, mean.max(), t[mean.argmax()], max(est),
              est_t[int(np.argmax(est))], -force[-1], a.out))


if __name__ == "__main__":
    main()
