#!/usr/bin/env python3
"""Plots of seed 002's blast (configs/seed002_blast_3d.yaml, the blast_wave reference;
docs/blast.md): the p-q stress paths of the probes P1-P3 with the granite's Mohr-Coulomb
envelope (triaxial compression and extension), and the probes' speeds against time with their
Fermat first-arrival times, for one or more runs (e.g. two resolutions).

  tools/blast_plot.py OUT_DIR [OUT_DIR ...] --png docs/seed002_blast.png
"""
import argparse
import csv
import json
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(run):
    with open(os.path.join(run, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(run, "verify.csv")) as f:
        rows = list(csv.DictReader(f))
    cols = {k: [float(r[k]) for r in rows] for k in rows[0]}
    return summary, cols


def envelope(material, p):
    """Mohr-Coulomb in p-q (compression positive): q = M (p + c cot phi), M = 6 sin phi /
    (3 -+ sin phi) for triaxial compression (-) and extension (+)."""
    s = math.sin(math.radians(material["phi"]))
    a = material["c"] / math.tan(math.radians(material["phi"]))
    return ([6 * s / (3 - s) * (x + a) for x in p], [6 * s / (3 + s) * (x + a) for x in p])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", help="output directories of blast runs")
    ap.add_argument("--png", required=True, help="figure to write")
    args = ap.parse_args()
    fig, (ax_pq, ax_v) = plt.subplots(1, 2, figsize=(13, 5))
    styles = ["-", "--", ":"]
    colours = {"P1": "C0", "P2": "C1", "P3": "C2", "S1": "C3", "S2": "C4"}
    granite = None
    for k, run in enumerate(args.runs):
        summary, cols = load(run)
        granite = summary["config"]["bodies"][0]["material"]
        cell = summary["config"]["grid"]["cell_size"]
        cell = cell[0] if isinstance(cell, list) else cell
        v = summary["verify"]
        for name in ["P1", "P2", "P3"]:
            ax_pq.plot([x / 1e3 for x in cols["p_" + name]], [x / 1e3 for x in cols["q_" + name]],
                       styles[k % 3], color=colours[name], label=f"{name}, {cell} m cells")
        for name in colours:
            if "speed_" + name not in cols:
                continue
            t = [1e3 * x for x in cols["time"]]
            ax_v.semilogy(t, cols["speed_" + name], styles[k % 3], color=colours[name],
                          label=f"{name}, {cell} m cells")
            if k == 0:
                ax_v.axvline(1e3 * v["expected_arrival_" + name], color=colours[name], lw=0.8,
                             alpha=0.6)
    p = [0, 1.0e6]
    comp, ext = envelope(granite, p)
    ax_pq.plot([x / 1e3 for x in p], [x / 1e3 for x in comp], "k-", lw=1,
               label="granite MC, compression")
    ax_pq.plot([x / 1e3 for x in p], [x / 1e3 for x in ext], "k--", lw=1,
               label="granite MC, extension")
    ax_pq.set_xlim(0, 1000)
    ax_pq.set_ylim(0, 2500)
    ax_pq.set_xlabel("p (kPa, compression positive)")
    ax_pq.set_ylabel("q (kPa)")
    ax_pq.set_title("stress paths at 20 m depth")
    ax_pq.legend(fontsize=7)
    ax_v.set_xlabel("time (ms)")
    ax_v.set_ylabel("speed (m/s)")
    ax_v.set_ylim(1e-7, 1e-1)
    ax_v.set_title("probe speeds; vertical lines: Fermat first arrivals")
    ax_v.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(args.png, dpi=110)
    print("wrote", args.png)


if __name__ == "__main__":
    main()
