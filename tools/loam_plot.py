"""One figure of any loam run: the particles of a frame coloured by a field, the run's history
(energies against time) and its verify series beside the reference. `loam plot RUN` calls this
with the interpreter loam uses for its other figures; the scene figures (the other tools/*.py)
read the same files, with frames_of_set for the frame index.

Usage: loam plot RUN [--field F] [--frame N] [--set S] [--out FILE]
  F: a particle field of the frame (velocity, stress, pore_pressure, plastic_strain_eq, ...);
     a vector is drawn as its magnitude, the stress as its mean p = -(xx + yy + zz) / 3; F:K
     draws component K (0-based; stress in Voigt order xx, yy, zz, xy, yz, xz).
  N: the frame's index (0 the first, -1 the last, the default).
Exit codes: 0 drawn, 2 bad input (no such run, field or frame: the message lists what there is),
1 the Python modules are missing (Debian packages python3-h5py, python3-matplotlib)."""
import argparse
import csv
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

MISSING_MODULES = 1
BAD_INPUT = 2
DEFAULT_FIELDS = ("plastic_strain_eq", "pore_pressure", "displacement", "velocity", "stress")
TIME_KEYS = ("time", "t")


def fail(message, code=BAD_INPUT):
    print(f"loam plot: error: {message}", file=sys.stderr)
    sys.exit(code)


def frames_of_set(index_file):
    """[(time, [h5 files])] of one particle set's ParaView index: a temporal collection whose
    members are one uniform grid per frame, or (under mpirun) a spatial collection of one grid
    per rank."""
    root = ET.parse(index_file).getroot()
    folder = os.path.dirname(index_file)
    temporal = root.find("Domain/Grid")
    frames = []
    for grid in temporal.findall("Grid") if temporal is not None else []:
        t = grid.find(".//Time")
        files = sorted({d.text.split(":")[0] for d in grid.iter("DataItem")
                        if d.text and d.text.strip().endswith(":/position")})
        if t is not None and files:
            frames.append((float(t.get("Value")), [os.path.join(folder, f) for f in files]))
    return frames


def particle_sets(run):
    """{set name: frames} of every particle index in the run (the grid's index left out)."""
    sets = {}
    for name in sorted(os.listdir(run)):
        if name.endswith(".xdmf"):
            fr = frames_of_set(os.path.join(run, name))
            if fr:
                sets[name[:-len(".xdmf")]] = fr
    return sets


def read_frame(files):
    """{dataset: rows} of one frame over its rank files."""
    import h5py
    import numpy as np

    parts = {}
    for path in files:
        with h5py.File(path, "r") as f:
            for k in f:
                parts.setdefault(k, []).append(f[k][()])
    return {k: np.concatenate(v) for k, v in parts.items()}


def field_values(data, spec):
    """(values, label) of the field spec NAME or NAME:K in a frame's datasets."""
    import numpy as np

    name, _, comp = spec.partition(":")
    if name not in data:
        return None, f"no {name} (it has {', '.join(sorted(k for k in data if k != 'id'))})"
    a = data[name]
    if a.ndim == 1:
        return a, name
    if comp:
        if not comp.isdigit() or int(comp) >= a.shape[1]:
            return None, f"{name} has components 0 to {a.shape[1] - 1}"
        return a[:, int(comp)], f"{name}[{comp}]"
    if name == "stress":
        return -(a[:, :3].sum(axis=1)) / 3, "mean stress p = -tr(sigma)/3 (Pa)"
    return np.sqrt((a * a).sum(axis=1)), f"|{name}|"


def dimension(summary, positions):
    if "dimension" in summary:
        return int(summary["dimension"])
    used = [d for d in range(3) if positions[:, d].max() > positions[:, d].min()]
    return max(used) + 1 if used else 1


def draw_particles(ax, sets, args, summary):
    """The chosen frame of each set (or of --set) coloured by the field; the field's name."""
    import numpy as np

    chosen = {args.set: sets[args.set]} if args.set else sets
    field, label, sc, t = args.field, None, None, None
    frames = {}
    for name, fr in sorted(chosen.items()):
        if not -len(fr) <= args.frame < len(fr):
            fail(f"--frame {args.frame}: set {name} has frames 0 to {len(fr) - 1} "
                 f"(or -1 to -{len(fr)} from the last)")
        frames[name] = (fr[args.frame][0], read_frame(fr[args.frame][1]))
    if not field:
        present = set().union(*(d.keys() for _, d in frames.values()))
        field = next((f for f in DEFAULT_FIELDS if f in present), "")
    missing, spans = [], []
    dim, t = int(summary.get("dimension", 2)), next(iter(frames.values()))[0]
    size = max(0.3, 4000.0 / max(sum(len(d["position"]) for _, d in frames.values()), 1))
    drawn = {n: field_values(d, field) if field else (None, "") for n, (_, d) in frames.items()}
    # the sets without the field first, in grey, under those that have it
    for name in sorted(frames, key=lambda n: drawn[n][0] is not None):
        time, data = frames[name]
        x = data["position"]
        if len(x) == 0:  # a set with no particles yet (a source's) or any more (a sink's)
            continue
        dim = dimension(summary, x)
        values, text = drawn[name]
        t = time
        if values is None and field:
            missing.append(f"set {name}: {text}")
        label = text if values is not None else label
        tag = name if values is not None or not field else f"{name} (no {field})"
        if dim == 1:
            if values is not None:  # a 1D set without the field has nothing to show
                ax.plot(x[:, 0], values, ".", ms=3, label=tag)
            continue
        spans.append((np.ptp(x[:, 0]), np.ptp(x[:, dim - 1])))
        if values is None:
            ax.scatter(x[:, 0], x[:, dim - 1], s=size, c="0.75", label=tag)
        else:
            sc = ax.scatter(x[:, 0], x[:, dim - 1], s=size, c=values, cmap="viridis", label=tag)
    if missing and len(missing) == len(frames):
        fail(f"--field {field}: " + "; ".join(missing))
    width = max((s[0] for s in spans), default=0)
    height = max((s[1] for s in spans), default=0)
    if spans and 0.1 < height / max(width, 1e-30) < 10:
        ax.set_aspect("equal")  # the body's shape, unless it is a thin column or layer
    if sc is not None:
        ax.figure.colorbar(sc, ax=ax, label=label or "", shrink=0.8)
    ax.set_ylabel(("z (m)" if dim == 3 else "y (m)") if dim > 1 else (label or ""))
    ax.set_xlabel("x (m)")
    if len(frames) > 1:
        ax.legend(fontsize=7, markerscale=3)
    ax.set_title(f"t = {t:.4g} s" + (f", {label}" if label else "") +
                 (" (side view x-z)" if dim == 3 else ""), fontsize=9)


def read_csv(path):
    """{column: [floats]} of a CSV with a header (non-numbers as nan)."""
    cols = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            for k, v in row.items():
                try:
                    cols.setdefault(k, []).append(float(v))
                except (TypeError, ValueError):
                    cols.setdefault(k, []).append(math.nan)
    return cols


def draw_history(ax, run):
    path = os.path.join(run, "history.csv")
    if not os.path.exists(path):
        ax.text(0.5, 0.5, "no history.csv", ha="center", transform=ax.transAxes)
        return
    h = read_csv(path)
    t = h.get("time", [])
    for k in ("kinetic_energy", "strain_energy", "total_energy", "energy_balance"):
        if k in h and any(v != 0 for v in h[k] if not math.isnan(v)):
            ax.plot(t, h[k], label=k)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("energy (J)")
    ax.set_title("history.csv", fontsize=9)
    if ax.lines:
        ax.legend(fontsize=7)


def number(v):
    """A summary value (JSON null is a NaN loam could not measure)."""
    return "nan" if v is None else f"{v:.4g}"


def draw_verify(ax, run, summary):
    """verify.csv's series against its first column, and the comparisons of summary.json."""
    verify = summary.get("verify", {})
    lines = [f"{c['measured']} {number(c['value'])} vs {c['reference']} "
             f"{number(c['reference_value'])}" for c in verify.get("comparisons", [])]
    lines += [f"{k} {number(v)}" for k, v in verify.items()
              if "error" in k and (v is None or isinstance(v, (int, float))) and "_T" not in k][:6]
    path = os.path.join(run, "verify.csv")
    if os.path.exists(path):
        s = read_csv(path)
        keys = list(s)
        for k in keys[1:7]:
            ax.plot(s[keys[0]], s[k], label=k)
        ax.set_xlabel(keys[0])
        if ax.lines:
            ax.legend(fontsize=7)
    else:
        ax.axis("off")
    title = f"verify: {verify.get('reference', 'none')}"
    ax.set_title(title, fontsize=9)
    if lines:
        ax.text(0.02, 0.98, "\n".join(lines), va="top", fontsize=7, transform=ax.transAxes,
                bbox=dict(facecolor="white", alpha=0.8, lw=0))


def main():
    ap = argparse.ArgumentParser(prog="loam plot", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", help="a run's output directory")
    ap.add_argument("--field", default="")
    ap.add_argument("--frame", type=int, default=-1)
    ap.add_argument("--set", default="", help="one particle set (default: all)")
    ap.add_argument("--out", default="", help="PNG file (default RUN/plot.png)")
    a = ap.parse_args()
    if not os.path.isdir(a.run):
        fail(f"{a.run}: no such run directory")
    try:
        import h5py  # noqa: F401
        import matplotlib
    except ImportError as e:
        fail(f"{e}: install the Debian packages python3-h5py and python3-matplotlib "
             "(tools/setup.sh does)", MISSING_MODULES)
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    summary_file = os.path.join(a.run, "summary.json")
    summary = json.load(open(summary_file)) if os.path.exists(summary_file) else {}
    sets = particle_sets(a.run)
    if not sets:
        fail(f"{a.run}: no particle frames (no *.xdmf index; output.every_time writes them)")
    if a.set and a.set not in sets:
        fail(f"--set {a.set}: the run's sets are {', '.join(sets)}")
    fig = plt.figure(figsize=(10, 7.5))
    grid = fig.add_gridspec(2, 2, height_ratios=(1.4, 1))
    draw_particles(fig.add_subplot(grid[0, :]), sets, a, summary)
    draw_history(fig.add_subplot(grid[1, 0]), a.run)
    draw_verify(fig.add_subplot(grid[1, 1]), a.run, summary)
    fig.suptitle(f"{os.path.basename(os.path.normpath(a.run))}: status "
                 f"{summary.get('status', 'unknown (no summary.json)')}", fontsize=10)
    fig.tight_layout()
    out = a.out or os.path.join(a.run, "plot.png")
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()
