#!/usr/bin/env python3
"""Observed convergence orders from a `loam compare` CSV: for each series (e.g. shape_function),
fit log(error) = p log(h) + c by least squares over the resolutions and print a Markdown table;
optionally plot error against h. Usage:
  convergence.py compare.csv --metric displacement_error [--h grid.cell_size]
                 [--series shape_function] [--plot conv.png]"""
import argparse
import csv
import math


def fit_order(hs, es):
    xs, ys = [math.log(h) for h in hs], [math.log(e) for e in es]
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("csv")
    ap.add_argument("--metric", required=True)
    ap.add_argument("--h", default="grid.cell_size")
    ap.add_argument("--series", default="shape_function")
    ap.add_argument("--plot", default="")
    a = ap.parse_args()
    rows = [r for r in csv.DictReader(open(a.csv)) if r["status"] == "ok" and r.get(a.metric)]
    series = {}
    for r in rows:
        series.setdefault(r[a.series], []).append((float(r[a.h]), float(r[a.metric]),
                                                   float(r["wall_seconds"])))
    hs_all = sorted({h for s in series.values() for h, _, _ in s}, reverse=True)
    print(f"| {a.series} | " + " | ".join(f"h = {h:g}" for h in hs_all) + " | observed order |")
    print("|---|" + "---|" * (len(hs_all) + 1))
    for name, pts in sorted(series.items()):
        pts.sort(reverse=True)
        by_h = {h: e for h, e, _ in pts}
        order = fit_order([h for h, _, _ in pts], [e for _, e, _ in pts])
        cells = " | ".join(f"{by_h[h]:.3e}" if h in by_h else "" for h in hs_all)
        print(f"| {name} | {cells} | {order:.2f} |")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4.5))
        for name, pts in sorted(series.items()):
            pts.sort()
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=name)
        ax.set_xlabel(a.h + " (m)")
        ax.set_ylabel(a.metric)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)


if __name__ == "__main__":
    main()
