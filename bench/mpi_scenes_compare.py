"""Compare a serial run's summary.json with the same scene's run on ranks (bench/mpi_scenes.sh):
speed, steps, every stage's record and every verify metric, side by side."""
import json
import sys


def load(path):
    with open(path + "/summary.json") as f:
        return json.load(f)


def rel(a, b):
    if not isinstance(a, (int, float)) or not isinstance(b, (int, float)):
        return ""
    scale = max(abs(a), abs(b))
    return f"{abs(a - b) / scale:.2e}" if scale > 0 else "0"


def main(serial_dir, ranks_dir):
    a, b = load(serial_dir), load(ranks_dir)
    name = a["config"] if isinstance(a.get("config"), str) else serial_dir
    print(f"== {name}")
    print(f"  particles {a['particles']} / {b['particles']}, steps {a['steps']} / {b['steps']}, "
          f"status {a['status']} / {b['status']}")
    sa, sb = a["particle_steps_per_second"], b["particle_steps_per_second"]
    print(f"  1x2 threads {sa / 1e6:.2f} M particle-steps/s, {a['wall_seconds']:.1f} s; "
          f"2 ranks x 1 {sb / 1e6:.2f} M, {b['wall_seconds']:.1f} s; ratio {sb / sa:.2f}")
    for key in ("stages", "strength_reduction"):
        if key in a:
            print(f"  {key}:")
            xa, xb = a[key], b.get(key)
            if isinstance(xa, list):
                for k, (ra, rb) in enumerate(zip(xa, xb or [])):
                    fields = [f"{f} {ra[f]:.6g}/{rb[f]:.6g} ({rel(ra[f], rb[f])})"
                              for f in ra if isinstance(ra[f], (int, float)) and f in rb]
                    print(f"    {ra.get('name', k)}: " + ", ".join(fields))
            else:
                for f in xa:
                    if isinstance(xa[f], (int, float)):
                        print(f"    {f}: {xa[f]:.6g} / {xb.get(f)} ({rel(xa[f], xb.get(f))})")
    for k, va in a.get("verify", {}).items():
        vb = b.get("verify", {}).get(k)
        if isinstance(va, (int, float)):
            print(f"  verify.{k}: {va:.6g} / {vb:.6g} (relative difference {rel(va, vb)})")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
