#!/usr/bin/env python3
"""Plot normalised pore pressure p/p0 against depth from a two-phase run's particle frames, at
the frames nearest to the requested time factors T = c_v t / H^2, beside Terzaghi's series
(docs/verification.md C) evaluated at each frame's own time.
Usage: terzaghi_plot.py RUN_DIR --cv 1.0194 --H 1 --p0 1e4 [--T 0.05 0.1 0.2 0.5 1] --out x.png
The vertical axis is the last coordinate; depth is measured from the initial top of the column."""
import argparse
import math

from loam_plot import frames_of_set


def terzaghi(zr, T):
    """p/p0 at relative depth zr = z'/H (0 at the drained top) and time factor T."""
    if T <= 0:
        return 1.0
    s = 0.0
    for m in range(2000):
        M = (2 * m + 1) * math.pi / 2
        term = 2 / M * math.sin(M * zr) * math.exp(-M * M * T)
        s += term
        if M * M * T > 50:
            break
    return s


def frames(run_dir):
    """(time, path) of every particle frame of a run (loam_plot.frames_of_set reads the ParaView
    index; a frame split over ranks by its first file)."""
    return [(t, files[0]) for t, files in frames_of_set(run_dir + "/particles.xdmf")]


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("run_dir")
    ap.add_argument("--cv", type=float, required=True, help="consolidation coefficient (m^2/s)")
    ap.add_argument("--H", type=float, required=True, help="drainage length (m)")
    ap.add_argument("--p0", type=float, required=True, help="applied load (Pa)")
    ap.add_argument("--T", type=float, nargs="+", default=[0.05, 0.1, 0.2, 0.5, 1.0])
    ap.add_argument("--out", default="terzaghi.png")
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    import h5py
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fr = frames(a.run_dir)
    fig, ax = plt.subplots(figsize=(5.5, 5))
    colors = plt.cm.viridis([i / max(1, len(a.T) - 1) for i in range(len(a.T))])
    for T, c in zip(a.T, colors):
        t_want = T * a.H ** 2 / a.cv
        t, name = min(fr, key=lambda f: abs(f[0] - t_want))
        with h5py.File(name) as f:
            pos = f["position"][:]
            p = f["pore_pressure"][:]
        # the vertical axis is the last non-trivial coordinate (y in 2D, x in 1D)
        axis = 1 if abs(pos[:, 1]).max() > 0 else 0
        if abs(pos[:, 2]).max() > 0:
            axis = 2
        z = pos[:, axis]
        with h5py.File(fr[0][1]) as f0:
            z0 = sorted(set(f0["position"][:, axis]))
            top = z0[-1] + 0.5 * (z0[1] - z0[0])  # particle domains: half a spacing above
        depth = top - z
        Tf = a.cv * t / a.H ** 2
        ax.plot(p / a.p0, depth, "o", ms=3, color=c, label=f"loam T = {Tf:.3g}")
        zz = [a.H * i / 200 for i in range(201)]
        ax.plot([terzaghi(zi / a.H, Tf) for zi in zz], zz, "-", color=c, lw=1)
    ax.plot([], [], "k-", lw=1, label="Terzaghi series")
    ax.invert_yaxis()
    ax.set_xlabel("p / p0")
    ax.set_ylabel("depth below the drained top (m)")
    ax.set_xlim(0, 1.1)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(a.title or "Terzaghi consolidation")
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)


if __name__ == "__main__":
    main()
