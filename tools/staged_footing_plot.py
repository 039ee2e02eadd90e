#!/usr/bin/env python3
"""Plot a staged footing run (configs/seed004_slope_staged.yaml): the strip's settlement and the
volumetric strain V/V0 - 1 at the probes below it at the end of each load stage, counted from the
state after the gravity stages (the first stage with `reset:`), against the stage's load.
Usage: staged_footing_plot.py RUN_DIR --out x.png [--first-load-stage 2] [--load-step 15]"""
import argparse
import csv
import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

PROBES = [("strip_surface", "0 m"), ("strip_3m", "3 m"), ("strip_6m", "6 m")]


def read_probe(run_dir, name):
    with open(f"{run_dir}/probe_{name}.csv") as f:
        return [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]


def at(rows, t):
    """The last sample at or before time t (a stage's end is always sampled)."""
    return [r for r in rows if r["time"] <= t * (1 + 1e-9)][-1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--out", required=True)
    ap.add_argument("--first-load-stage", type=int, default=2,
                    help="index of the first load stage (after the gravity stages)")
    ap.add_argument("--load-step", type=float, default=15.0, help="kPa added per stage")
    a = ap.parse_args()
    with open(a.run_dir + "/summary.json") as f:
        stages = [s for s in json.load(f)["stages"] if s["status"] != "not_run"]
    probes = {name: read_probe(a.run_dir, name) for name, _ in PROBES}
    t0 = stages[a.first_load_stage]["start_time"]
    ref = {name: at(rows, t0) for name, rows in probes.items()}
    loads, settlement, strain, status = [], [], {n: [] for n, _ in PROBES}, []
    for k, s in enumerate(stages[a.first_load_stage:]):
        loads.append(a.load_step * (k + 1))
        status.append(s["status"])
        top = at(probes["strip_surface"], s["end_time"])
        settlement.append(ref["strip_surface"]["position_y"] - top["position_y"])
        for name, _ in PROBES:
            r = at(probes[name], s["end_time"])
            strain[name].append(r["volume"] / ref[name]["volume"] - 1)
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4))
    static = [i for i, s in enumerate(status) if s == "static"]
    other = [i for i, s in enumerate(status) if s != "static"]
    ax.plot([loads[i] for i in static], [settlement[i] for i in static], "o-", ms=4,
            label="loam, static at the stage's end")
    if other:
        ax.plot([loads[i] for i in other], [settlement[i] for i in other], "rx", ms=8,
                label="no static state within the stage (" + status[other[0]] + ")")
    ax.axvline(150, color="grey", ls=":", lw=1, label="PLAXIS (seed 004): last converged stage")
    ax.set_xlabel("strip load (kPa)")
    ax.set_ylabel("settlement under the strip centre (m)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    for name, label in PROBES:
        bx.plot(loads, strain[name], "o-", ms=3, label=label + " below the strip centre")
    bx.set_xlabel("strip load (kPa)")
    bx.set_ylabel("volumetric strain V/V0 - 1 (compression < 0)")
    bx.grid(alpha=0.3)
    bx.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)


if __name__ == "__main__":
    main()
