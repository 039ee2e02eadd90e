#!/usr/bin/env python3
"""Plot the scour depth against time of water-jet runs (the scour_depth reference's verify.csv,
configs/seed003_water_jet_*.yaml), one curve per run.
Usage: scour_plot.py --run LABEL=RUN_DIR [--run LABEL=RUN_DIR ...] --title T --out x.png
A run directory may also be a `loam compare` variant directory (it holds verify.csv)."""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def series(run_dir):
    with open(run_dir + "/verify.csv") as f:
        rows = list(csv.DictReader(f))
    return [float(r["time"]) for r in rows], [float(r["scour_depth"]) for r in rows]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--run", action="append", required=True, help="LABEL=RUN_DIR")
    ap.add_argument("--title", default="scour depth on the jet axis")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    fig, ax = plt.subplots(figsize=(6, 4))
    for spec in a.run:
        label, run_dir = spec.split("=", 1)
        t, d = series(run_dir)
        ax.plot(t, d, marker="o", ms=3, label=label)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("scour depth (m)")
    ax.set_title(a.title)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)


if __name__ == "__main__":
    main()
