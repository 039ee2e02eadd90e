#!/usr/bin/env python3
"""Seed 002 dynamic consolidation (docs/verification.md C; seed paper Figs. 5 and 6): pore pressure
p/p0 against depth at the requested times for a fixed-base and an absorbing-base run, beside
Terzaghi's series at each frame's own time, and the pore pressure of the deepest particle
against time for both runs (probe_base.csv).
Usage:
  loam run configs/seed002_dynamic_consolidation.yaml --out results/seed002_fixed
  loam run configs/seed002_dynamic_consolidation_absorbing.yaml --out results/seed002_absorbing
  seed002_plot.py results/seed002_fixed results/seed002_absorbing --cv 1 --H 1 --p0 1e3 \\
      --out docs/seed002_dynamic_consolidation.png
The vertical axis is the last coordinate; depth is measured from each frame's current top
(half a particle spacing above the highest particle), as the terzaghi reference does."""
import argparse
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from terzaghi_plot import frames, terzaghi  # noqa: E402


def profiles(ax, run_dir, times, a, title):
    import h5py
    import matplotlib.pyplot as plt

    fr = frames(run_dir)
    with h5py.File(fr[0][1]) as f0:
        pos0 = f0["position"][:]
    axis = max(d for d in range(pos0.shape[1]) if abs(pos0[:, d]).max() > 0)
    z0 = sorted(set(pos0[:, axis]))
    half = 0.5 * (z0[1] - z0[0])  # half a particle spacing
    colors = plt.cm.viridis([i / max(1, len(times) - 1) for i in range(len(times))])
    for t_want, c in zip(times, colors):
        t, name = min(fr, key=lambda f: abs(f[0] - t_want))
        with h5py.File(name) as f:
            z = f["position"][:, axis]
            p = f["pore_pressure"][:]
        depth = z.max() + half - z
        ax.plot(p / a.p0, depth, "o", ms=2.5, color=c, label=f"loam t = {t:.3g} s")
        T = a.cv * t / a.H ** 2
        zz = [a.H * i / 200 for i in range(201)]
        ax.plot([terzaghi(zi / a.H, T) for zi in zz], zz, "-", color=c, lw=1)
    ax.plot([], [], "k-", lw=1, label="Terzaghi series")
    ax.invert_yaxis()
    ax.set_xlabel("p / p0")
    ax.set_ylabel("depth below the drained top (m)")
    ax.set_xlim(0, 1.6)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper right")
    ax.set_title(title, fontsize=10)


def base_history(ax, run_dir, a, label, style):
    t, p = [], []
    with open(run_dir + "/probe_base.csv") as f:
        for row in csv.DictReader(f):
            t.append(float(row["time"]))
            p.append(float(row["pore_pressure"]) / a.p0)
    ax.plot(t, p, style, lw=0.8, label=label)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("fixed_run")
    ap.add_argument("absorbing_run")
    ap.add_argument("--cv", type=float, required=True, help="consolidation coefficient (m^2/s)")
    ap.add_argument("--H", type=float, required=True, help="drainage length (m)")
    ap.add_argument("--p0", type=float, required=True, help="applied load (Pa)")
    ap.add_argument("--times", type=float, nargs="+", default=[0.02, 0.1, 0.2, 0.5, 1.0],
                    help="times of the profiles (s)")
    ap.add_argument("--history_end", type=float, default=0.2, help="end of the base history (s)")
    ap.add_argument("--out", default="seed002_dynamic_consolidation.png")
    a = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(1, 3, figsize=(15, 5))
    profiles(axs[0], a.fixed_run, a.times, a, "fixed (impervious) base")
    profiles(axs[1], a.absorbing_run, a.times, a, "impermeable absorbing base (rho_sat c_u)")
    base_history(axs[2], a.fixed_run, a, "fixed base", "C3-")
    base_history(axs[2], a.absorbing_run, a, "absorbing base", "C0-")
    ts = [a.history_end * i / 400 for i in range(1, 401)]
    axs[2].plot(ts, [terzaghi(1.0, a.cv * t / a.H ** 2) for t in ts], "k--", lw=1,
                label="Terzaghi (base)")
    axs[2].set_xlim(0, a.history_end)
    axs[2].set_xlabel("t (s)")
    axs[2].set_ylabel("p / p0 of the deepest particle")
    axs[2].grid(True, alpha=0.3)
    axs[2].legend(fontsize=8)
    axs[2].set_title("pore pressure at the base (paper Fig. 6)", fontsize=10)
    fig.suptitle("Seed 002 dynamic consolidation: 1 m column, 1 kPa step load, "
                 "c_v = 1 m^2/s, undrained wave 656 m/s", fontsize=11)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)


if __name__ == "__main__":
    main()
