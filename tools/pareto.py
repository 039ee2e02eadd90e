#!/usr/bin/env python3
"""Plot error against wall time from a `loam compare` CSV (log-log), one series per value of an
axis (e.g. shape_function), with the Pareto front (no other variant both faster and more accurate)
marked. Usage: pareto.py compare.csv --out pareto.png [--series AXIS] [--metric NAME]"""
import argparse
import csv
import math
import sys


def flow_map(text):
    """A flat flow map as `loam compare` writes a map-valued axis ('{a: 1, b: x}'), or None."""
    t = text.strip()
    if not (t.startswith("{") and t.endswith("}")):
        return None
    pairs = [p.split(":", 1) for p in t[1:-1].split(",") if p.strip()]
    if any(len(p) != 2 for p in pairs):
        return None
    return {k.strip(): v.strip() for k, v in pairs}


def short_labels(values):
    """Series labels: a map-valued axis is named by the keys that differ between its values."""
    maps = {v: flow_map(v) for v in values}
    if not values or any(m is None for m in maps.values()):
        return {v: v for v in values}
    keys = sorted({k for m in maps.values() for k in m})
    differ = [k for k in keys if len({maps[v].get(k) for v in values}) > 1]
    return {v: ", ".join(f"{k}: {maps[v][k]}" for k in differ if k in maps[v]) or v for v in values}


def number(text):
    """A CSV cell as a number (an empty cell, a failed variant's: nan)."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return float("nan")


def nothing_to_plot(reason):
    print(reason, file=sys.stderr)
    sys.exit(2)


def mark_left_out(ax, left_out, metric):
    """Variants without a plotted point (failed, unstable, no metric): a red x at their wall
    time on the top edge, and their names in a note; listed on stdout too."""
    if not left_out:
        return
    timed = [r for r in left_out if r[0] > 0 and math.isfinite(r[0])]
    if timed:
        ax.scatter([r[0] for r in timed], [0.97] * len(timed), marker="x", color="red", s=60,
                   transform=ax.get_xaxis_transform(), clip_on=False,
                   label="not plotted (at its wall time)")
    note = "\n".join(f"{v}: {status}, {metric} {m}" for _, v, status, m in left_out[:8])
    more = f"\n... and {len(left_out) - 8} more" if len(left_out) > 8 else ""
    ax.text(0.99, 0.90, "not plotted:\n" + note + more, transform=ax.transAxes, fontsize=6,
            ha="right", va="top", color="red", bbox=dict(facecolor="white", alpha=0.8, lw=0))
    print("not plotted, marked in red: " +
          "; ".join(f"{v} ({status})" for _, v, status, _ in left_out))


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("csv")
    ap.add_argument("--out", default="pareto.png")
    ap.add_argument("--series", default="")
    ap.add_argument("--metric", default="")
    a = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = list(csv.DictReader(open(a.csv)))
    if not rows:
        nothing_to_plot("no rows in " + a.csv)
    metric = a.metric or next((k for k in rows[0] if "error" in k), "")
    if not metric or metric not in rows[0]:
        nothing_to_plot(f"no column {metric!r} in {a.csv}" if metric else
                        "no column named *error* (pass --metric NAME)")
    series = a.series if a.series in rows[0] else None
    pts, left_out = [], []
    for r in rows:
        t, e = number(r.get("wall_seconds")), abs(number(r.get(metric)))  # a signed error's size
        if r["status"] == "ok" and t > 0 and e > 0 and math.isfinite(e):
            pts.append((t, e, r[series] if series else "all", r["variant"]))
        else:
            left_out.append((t, r["variant"], r["status"], r.get(metric) or "-"))
    if not pts:
        nothing_to_plot("no variant ran ok with a positive " + metric)
    fig, ax = plt.subplots(figsize=(7, 5))
    names = sorted({p[2] for p in pts})
    labels = short_labels(names)
    for name in names:
        s = sorted((p for p in pts if p[2] == name), key=lambda p: p[0])
        ax.plot([p[0] for p in s], [p[1] for p in s], "o-", label=labels[name], alpha=0.8)
    # Pareto front: sorted by time, keep points that improve on the best error so far.
    front, best = [], float("inf")
    for p in sorted(pts, key=lambda p: (p[0], p[1])):
        if p[1] < best:
            front.append(p)
            best = p[1]
    ax.plot([p[0] for p in front], [p[1] for p in front], "k--", lw=1, label="Pareto front")
    ax.scatter([p[0] for p in front], [p[1] for p in front], s=120, facecolors="none",
               edgecolors="k")
    mark_left_out(ax, left_out, metric)
    ax.set_xscale("log")
    times = [p[0] for p in pts] + [r[0] for r in left_out if r[0] > 0 and math.isfinite(r[0])]
    ax.set_xlim(min(times) / 1.5, max(times) * 1.5)  # the failed variants' marks in view
    ax.set_yscale("log")
    ax.set_xlabel("wall time per run (s)")
    ax.set_ylabel(f"|{metric}|")
    ax.set_title("speed against error" + (f" by {series}" if series else ""))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)


if __name__ == "__main__":
    main()
