#!/usr/bin/env python3
"""Seed 001 large-strain consolidation (configs/seed001_large_strain.yaml), as the paper's Fig. 3:
(a) p/p0 against the normalised depth (measured from the current top, over the current height)
at time factors T_L = c_v t / H0^2 (H0 the initial height), beside Terzaghi's small-strain
series; (b) column height against T_L, with the exact final heights and the paper's values.
Height = sum of particle volumes / initial cross-section (the `volume` output field is needed).
Usage: large_strain_plot.py --run jaumann DIR --run hencky DIR --cv 0.0102 --p0 5e4 --out x.png
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from terzaghi_plot import frames, terzaghi  # noqa: E402  (small-strain series, p/p0 at zeta and T)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--run", nargs=2, action="append", metavar=("LABEL", "DIR"), required=True)
    ap.add_argument("--cv", type=float, required=True, help="c_v = k M / gamma_w (m^2/s)")
    ap.add_argument("--p0", type=float, required=True, help="load (Pa)")
    ap.add_argument("--H0", type=float, default=1.0, help="initial height (m)")
    ap.add_argument("--T", type=float, nargs="+", default=[0.05, 0.1, 0.2, 0.5])
    ap.add_argument("--exact", type=float, nargs="*", default=[], help="exact final heights")
    ap.add_argument("--paper", type=float, nargs="*", default=[], help="paper final heights")
    ap.add_argument("--out", default="large_strain.png")
    a = ap.parse_args()
    import h5py
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.8))
    colors = plt.cm.viridis([i / max(1, len(a.T) - 1) for i in range(len(a.T))])
    styles = ["o", "s", "^", "v"]
    for r, (label, run_dir) in enumerate(a.run):
        fr = frames(run_dir)
        with h5py.File(fr[0][1]) as f:
            area = f["volume"][:].sum() / a.H0
        # (a) profiles at the frames nearest to the requested T_L
        for T, c in zip(a.T, colors):
            t, name = min(fr, key=lambda f: abs(f[0] - T * a.H0 ** 2 / a.cv))
            with h5py.File(name) as f:
                pos = f["position"][:]
                z = pos[:, max(i for i in range(3) if abs(pos[:, i]).max() > 0)]
                p = f["pore_pressure"][:]
                h = f["volume"][:].sum() / area
            top = z.max() + 0.5 * (h - (z.max() - z.min())) if len(z) > 1 else z.max()
            ax.plot(p / a.p0, (top - z) / h, styles[r % 4], ms=3, color=c, mfc="none" if r else c,
                    label=f"{label} T_L = {a.cv * t / a.H0 ** 2:.3g}")
        # (b) height against T_L
        ts, hs = [], []
        for t, name in fr:
            with h5py.File(name) as f:
                hs.append(f["volume"][:].sum() / area)
            ts.append(a.cv * t / a.H0 ** 2)
        bx.plot(ts[1:], hs[1:], "-", label=f"loam {label} (final {hs[-1]:.4f} m)")
    zz = [i / 200 for i in range(201)]
    for T, c in zip(a.T, colors):
        ax.plot([terzaghi(z, T) for z in zz], zz, "-", color=c, lw=1)
    ax.plot([], [], "k-", lw=1, label="Terzaghi, small strain")
    ax.invert_yaxis()
    ax.set_xlabel("p / p0")
    ax.set_ylabel("depth / current height")
    ax.set_xlim(0, 1.1)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("(a) pore pressure")
    for v in a.exact:
        bx.axhline(v, color="k", ls="--", lw=0.8)
    for v in a.paper:
        bx.axhline(v, color="r", ls=":", lw=0.8)
    bx.plot([], [], "k--", lw=0.8, label="exact final heights")
    bx.plot([], [], "r:", lw=0.8, label="paper final heights (MPM 0.674, FEM 0.704)")
    bx.set_xscale("log")
    bx.set_xlabel("T_L = c_v t / H0^2")
    bx.set_ylabel("column height (m)")
    bx.grid(True, alpha=0.3)
    bx.legend(fontsize=7)
    bx.set_title("(b) height")
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)


if __name__ == "__main__":
    main()
