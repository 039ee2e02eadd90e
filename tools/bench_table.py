"""The current table of bench/RESULTS.md, regenerated from `loam bench --json`: scene, threads,
M particle-steps/s (the median of --repeat runs), bytes per particle, the ratio to the bare
one-file MPM step of the same dimension and thread count (when its source is given), date and
commit. Run it with nothing else busy on the machine (the host drifts; the bare step runs in the
same session, so the ratios are back to back).

Usage: bench_table.py [--loam build/loam] [--bare PATH/speed_limit.cpp] [--write bench/RESULTS.md]
  [--scenes S ...] [--repeat 3] [--steps 300]
Without --write the table goes to stdout; with it, the part of RESULTS.md between the markers
<!-- current table: begin --> and <!-- current table: end --> is replaced."""
import argparse
import datetime
import json
import os
import re
import subprocess
import sys
import tempfile

SCENES = ["elastic_block_2d", "elastic_block_3d", "fbar_elastic_block_2d",
          "two_phase_elastic_block_2d", "double_point_elastic_block_2d"]
GIMP_SCENES = ["elastic_block_2d", "apic_elastic_block_2d"]  # APIC needs a smooth shape (MUSL)
BEGIN, END = "<!-- current table: begin -->", "<!-- current table: end -->"


def loam_runs(loam, scenes, repeat, steps, shape="linear"):
    """One JSON object per scene and thread count (1 and 2)."""
    run = subprocess.run([loam, "bench", "--json", "--repeat", str(repeat), "--steps", str(steps),
                          "--threads", "1", "2", "--shape-functions", shape, "--scenes", *scenes],
                         capture_output=True, text=True)
    if run.returncode:
        sys.exit(run.stderr)
    return [json.loads(line) for line in run.stdout.splitlines() if line.startswith("{")]


def bare_runs(source, repeat, steps):
    """{(dimension, threads): median M particle-steps/s} of the bare step (MUSL)."""
    exe = os.path.join(tempfile.mkdtemp(), "speed_limit")
    subprocess.run(["g++", "-O3", "-fopenmp", "-std=c++17", source, "-o", exe], check=True)
    result = {}
    for dim in (2, 3):
        for threads in (1, 2):
            env = dict(os.environ, OMP_NUM_THREADS=str(threads))
            runs = []
            for _ in range(repeat):
                text = subprocess.run([exe, f"dim={dim}", "var=musl", f"steps={steps}", "warm=5"],
                                      check=True, capture_output=True, text=True, env=env).stdout
                runs.append(float(re.search(r"Mpss=([0-9.]+)", text).group(1)))
            result[(dim, threads)] = sorted(runs)[len(runs) // 2]
    return result


def table(runs, bare, commit, date):
    lines = [f"Measured {date} on {commit} (`tools/bench_table.py`: `loam bench --json`, medians "
             "of the repeats; the bare step's source given, its ratio in the same session).", "",
             "| scene | threads | M particle-steps/s | bytes/particle | loam / bare step | date "
             "| commit |", "|---|---|---|---|---|---|---|"]
    for r in runs:
        mpss = r["particle_steps_per_second"] / 1e6
        b = bare.get((r["dimension"], r["threads"]))
        ratio = f"{mpss / b:.2f}" if b else "-"
        lines.append(f"| {r['scene']} ({r['shape_function']}, {r['update']}) | {r['threads']} | "
                     f"{mpss:.2f} | {r['bytes_per_particle']} | {ratio} | {date} | {commit} |")
    if bare:
        lines += ["", "Bare step (MUSL, linear, M particle-steps/s): " + ", ".join(
            f"{d}D {t} thread(s) {v:.2f}" for (d, t), v in sorted(bare.items())) + "."]
    return "\n".join(lines)


def write_into(path, text):
    doc = open(path).read()
    if BEGIN not in doc or END not in doc:
        sys.exit(f"{path}: no {BEGIN} ... {END} markers")
    head, rest = doc.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    open(path, "w").write(head + BEGIN + "\n" + text + "\n" + END + tail)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--loam", default="build/loam")
    ap.add_argument("--bare", default="", help="the bare step's source (speed_limit.cpp)")
    ap.add_argument("--write", default="", help="RESULTS.md to update")
    ap.add_argument("--scenes", nargs="+", default=SCENES)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--steps", type=int, default=300)
    a = ap.parse_args()
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip() or "unknown"
    date = datetime.date.today().isoformat()
    bare = bare_runs(a.bare, a.repeat, a.steps) if a.bare else {}
    runs = loam_runs(a.loam, a.scenes, a.repeat, a.steps)
    if a.scenes == SCENES:
        runs += loam_runs(a.loam, GIMP_SCENES, a.repeat, a.steps, "gimp")
    text = table(runs, bare, commit, date)
    if a.write:
        write_into(a.write, text)
    else:
        print(text)


if __name__ == "__main__":
    main()
