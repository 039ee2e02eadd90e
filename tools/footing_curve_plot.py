#!/usr/bin/python3
"""Load-settlement curves of strip footings pushed at a constant velocity (configs/
strip_footing_contact_2d.yaml, strip_footing_rigid_2d.yaml; docs/verification.md A): the bearing
pressure q = -2 R_y / B of a half model from the footing's reaction in history.csv over s_u,
against the settlement v t, with Prandtl's (2 + pi) s_u.
Usage: footing_curve_plot.py RUN_DIR:LABEL [RUN_DIR:LABEL ...] [--B 1] [--su 1e4]
       [--velocity 0.02] [--reaction footing] [--average 0.005] [--out F]"""
import argparse
import csv
import math

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def curve(run_dir, reaction, width, su, velocity, average):
    """Settlement and q / s_u (moving mean over `average` of settlement) of one run."""
    rows = list(csv.DictReader(open(run_dir + "/history.csv")))
    s = np.array([float(r["time"]) for r in rows]) * velocity
    q = np.array([-2 * float(r["reaction_" + reaction + "_y"]) / width / su for r in rows])
    step = max(np.median(np.diff(s)), 1e-15)
    n = max(1, int(round(average / step)))
    return s[n // 2: len(s) - n // 2], np.convolve(q, np.ones(n) / n, mode="valid")[: len(s) - 2 * (n // 2)]


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("runs", nargs="+", help="RUN_DIR:LABEL")
    ap.add_argument("--B", type=float, default=1.0, help="footing width (m; the half model's 2x)")
    ap.add_argument("--su", type=float, default=1.0e4, help="undrained strength (Pa)")
    ap.add_argument("--velocity", type=float, default=0.02, help="the footing's speed (m/s)")
    ap.add_argument("--reaction", default="footing", help="the footing's reaction name")
    ap.add_argument("--average", type=float, default=0.005,
                    help="moving mean over this much settlement (m)")
    ap.add_argument("--out", default="footing_curves.png")
    a = ap.parse_args()
    fig, ax = plt.subplots(figsize=(8, 5))
    top = 2 + math.pi
    for spec in a.runs:
        run, label = spec.rsplit(":", 1)
        s, q = curve(run, a.reaction, a.B, a.su, a.velocity, a.average)
        ax.plot(s, q, lw=1.2, label=label)
        top = max(top, q.max())
        print("%s: q / s_u %.2f at %.3f m (last)" % (label, q[-1], s[-1]))
    ax.axhline(2 + math.pi, color="k", ls="--", lw=1, label=r"Prandtl $(2+\pi)\,s_u$")
    ax.set_xlabel("settlement (m)")
    ax.set_ylabel(r"$q / s_u$")
    ax.set_ylim(0, 1.1 * top)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)
    print("wrote", a.out)


if __name__ == "__main__":
    main()
