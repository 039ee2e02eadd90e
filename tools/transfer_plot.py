#!/usr/bin/env python3
"""Final deposits of granular-collapse runs side by side (docs/transfers.md): the particles of
each run's last frame coloured by their equivalent plastic strain, with the run-out and final
height from its summary.json beside Lube et al. (2005).
Usage: transfer_plot.py RUN_DIR:LABEL [RUN_DIR:LABEL ...] --out F"""
import argparse
import json
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from terzaghi_plot import frames  # noqa: E402  ((time, path) of a run's particle frames)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("runs", nargs="+", help="RUN_DIR:LABEL")
    ap.add_argument("--out", default="transfers.png")
    a = ap.parse_args()
    fig, axes = plt.subplots(len(a.runs), 1, figsize=(8, 2.3 * len(a.runs)), sharex=True)
    axes = axes if len(a.runs) > 1 else [axes]
    for ax, spec in zip(axes, a.runs):
        run, label = spec.rsplit(":", 1)
        t, path = frames(run)[-1]
        with h5py.File(path) as f:
            x = f["position"][:]
            eps = f["plastic_strain_eq"][:] if "plastic_strain_eq" in f else None
        v = json.load(open(os.path.join(run, "summary.json")))["verify"]
        sc = ax.scatter(x[:, 0], x[:, 1], s=0.6, c=eps, cmap="viridis", vmin=0, vmax=1)
        ax.set_aspect("equal")
        ax.set_ylim(0, 0.45)
        ax.set_xlim(0, 1.2)
        ax.set_ylabel("y (m)")
        ax.set_title(
            f"{label}, t = {t:.2f} s\nrun-out (L_f-L0)/L0 = {v['runout_ratio']:.2f} "
            f"(Lube {v['lube2005_runout_ratio']:.2f}), H_f/L0 = {v['height_ratio']:.2f} "
            f"(Lube {v['lube2005_height_ratio']:.2f}), largest speed {v['max_speed_final']:.3f} m/s",
            fontsize=8,
        )
    axes[-1].set_xlabel("x (m)")
    fig.tight_layout(rect=(0, 0, 0.88, 1))
    cax = fig.add_axes((0.9, 0.2, 0.02, 0.6))
    fig.colorbar(sc, cax=cax, label="plastic_strain_eq")
    fig.savefig(a.out, dpi=120)


if __name__ == "__main__":
    main()
