#!/usr/bin/env python3
"""Plot a `loam element-test` CSV: q against axial (or shear) strain, the stress path q against
p', and void ratio against ln p' (when the CSV has void ratios). Optional reference lines: the
critical state line q = M p' (--M) and a peak deviator stress (--q-peak).
Usage: element_test_plot.py test.csv --out test.png [--M 1.2] [--q-peak 300e3] [--title T]"""
import argparse
import csv
import math
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("csv")
    ap.add_argument("--out", default="element_test.png")
    ap.add_argument("--M", type=float, default=None, help="critical state ratio for q = M p'")
    ap.add_argument("--q-peak", type=float, default=None, help="analytic peak q (Pa)")
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    rows = list(csv.DictReader(open(a.csv)))
    if not rows:
        sys.exit("no rows in " + a.csv)
    col = {k: [float(r[k]) for r in rows] for k in rows[0]}
    kpa = [x / 1e3 for x in col["q"]]
    p = [x / 1e3 for x in col["p"]]
    shear = max(abs(x) for x in col["eps_xy"]) > max(abs(x) for x in col["eps_a"])
    strain = [2 * x for x in col["eps_xy"]] if shear else col["eps_a"]
    e = col["void_ratio"]
    has_e = all(math.isfinite(x) for x in e) and all(x > 0 for x in p)
    n = 3 if has_e else 2
    fig, ax = plt.subplots(1, n, figsize=(4.2 * n, 3.6))
    ax[0].plot([100 * s for s in strain], kpa, "k-")
    ax[0].set_xlabel("shear strain gamma_xy (%)" if shear else "axial strain eps_a (%)")
    ax[0].set_ylabel("q (kPa)")
    ax[1].plot(p, kpa, "k-")
    ax[1].set_xlabel("p' (kPa)")
    ax[1].set_ylabel("q (kPa)")
    if a.q_peak is not None:
        ax[0].axhline(a.q_peak / 1e3, color="tab:red", ls="--", label="analytic q")
        ax[0].legend(fontsize=8)
    if a.M is not None:
        pm = max(p)
        ax[1].plot([0, pm], [0, a.M * pm], color="tab:red", ls="--", label="CSL q = M p'")
        ax[1].legend(fontsize=8)
    if has_e:
        ax[2].semilogx(p, e, "k-")
        ax[2].xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        if max(p) < 10 * min(p):  # less than a decade: label the minor ticks, small
            ax[2].xaxis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
            ax[2].tick_params(axis="x", which="minor", labelsize=7)
        ax[2].set_xlabel("p' (kPa, log)")
        ax[2].set_ylabel("void ratio e")
    for x in ax:
        x.grid(True, alpha=0.3)
    fig.suptitle(a.title or a.csv.split("/")[-1])
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)


if __name__ == "__main__":
    main()
