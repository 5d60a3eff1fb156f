#!/usr/bin/env python3
"""bench/paper_scale.py: the paper's scale, one command.

Three measurements, each a plain `clothsim run` at the scene's defaults
(no step or solver flags), REPEAT times, the median reported:

  drape 20k   scenes/bench/sheet_ball.yaml, 100 x 100 quads, 12 frames from rest
  drape 80k   the same at 200 x 200 quads (repulsion thickness 2 mm, below
              half an edge), 12 frames from rest
  twist 0.5M  scenes/figures/twist.yaml at 1000 x 250 quads (501,000
              triangles, thickness 0.4 mm) resumed from a tangled state for
              2 frames: the state is a run folder made once by
                bench/twist_state.sh build out/twist_500k
              (frame 42, made at coarser resolutions and carried onto the
              fine cloth with run --start-from, which then simulates frame
              42 itself: about half an hour on 2 cores; not committed,
              about 1 GB) and given with --twist-state out/twist_500k. Without it
              the twist is skipped.
  twist0      the same twist's first frame from rest (--only twist0, not run
              by default: about 11 minutes a run on 2 cores)

For each: seconds per frame, steps and CG iterations per step, peak
memory, and the largest count of intersecting triangle pairs at a frame's
end (the verifier's, in frames.jsonl; must be 0). Then CG alone
(bench_cg_speed on the 200 x 200 sheet at the damped step) against a
STREAM triad measured in the same run: the bytes one CG iteration streams
(model below) over its time, as a fraction of the triad's bandwidth.

usage: bench/paper_scale.py [--build DIR] [--repeat N] [--only drape20k,drape80k,twist,twist0,cg]
                            [--twist-state DIR] [--out DIR]
Writes DIR/paper_scale.md (default out/paper_scale). A Release build is expected.
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from speed import ROOT, cpu_times, machine, timed_run, triad  # noqa: E402

SHEET = os.path.join(ROOT, "scenes", "bench", "sheet_ball.yaml")
TWIST_FRAMES = 2


def die(msg):
    sys.exit("paper_scale.py: " + msg)


def records(run_dir, after=0):
    """The frames.jsonl records of frames > after."""
    with open(os.path.join(run_dir, "frames.jsonl")) as f:
        recs = [json.loads(line) for line in f if line.strip()]
    return [r for r in recs if r["frame"] > after]


def case_row(name, runs, frames):
    """runs: [(wall, rss, records)]; the median run's counts."""
    runs.sort(key=lambda r: r[0])
    wall, _, recs = runs[len(runs) // 2]
    steps = sum(r["steps"] for r in recs)
    cg = sum(r["cg_iterations"] for r in recs)
    pairs = [r["intersections"] for r in recs if r.get("intersections") is not None]
    return {"case": name, "s_per_frame": statistics.median(r[0] for r in runs) / frames,
            "min": runs[0][0] / frames, "max": runs[-1][0] / frames, "runs": len(runs),
            "steps_per_frame": steps / frames, "cg_per_step": cg / max(steps, 1),
            "peak_mib": max(r[1] for r in runs),
            "max_pairs": max(pairs) if pairs else None, "frames_checked": len(pairs)}


def drape(exe, n, thickness, repeat, out):
    frames = 12
    args = [exe, "run", SHEET, "-q", "--frames", str(frames),
            "--set", "cloths.0.grid.resolution=[%d,%d]" % (n, n)]
    if thickness:
        args += ["--set", "self_collision.thickness=%g" % thickness]
    runs = []
    for k in range(repeat):
        d = os.path.join(out, "drape_%d" % n)
        wall, rss, _ = timed_run(args + ["-o", d], d + "_log")
        runs.append((wall, rss, records(d)))
        print("  drape %dx%d run %d: %.3f s/frame" % (n, n, k + 1, wall / frames),
              file=sys.stderr, flush=True)
    return case_row("drape %dx%d (%d triangles)" % (n, n, 2 * n * n), runs, frames)


TWIST = os.path.join(ROOT, "scenes", "figures", "twist.yaml")
TWIST_500K = ["--set", "cloths.0.grid.resolution=[1000,250]",
              "--set", "self_collision.thickness=0.0004"]


def twist_from_rest(exe, repeat, out):
    runs = []
    for k in range(repeat):
        d = os.path.join(out, "twist_rest")
        wall, rss, _ = timed_run([exe, "run", TWIST, "-q", "--frames", "1", "-o", d] + TWIST_500K,
                                 d + "_log")
        runs.append((wall, rss, records(d)))
        print("  twist from rest, run %d: %.1f s/frame" % (k + 1, wall), file=sys.stderr,
              flush=True)
    return case_row("twist (501,000 triangles), frame 1 from rest", runs, 1)


def twist(exe, state, repeat, out):
    done = max(r["frame"] for r in records(state))
    runs = []
    for k in range(repeat):
        d = os.path.join(out, "twist_resumed")
        shutil.rmtree(d, ignore_errors=True)
        shutil.copytree(state, d, symlinks=True)
        wall, rss, _ = timed_run([exe, "run", d, "--resume", "-q", "--frames", str(done + TWIST_FRAMES)],
                          d + "_log")
        runs.append((wall, rss, records(d, done)))
        print("  twist from frame %d, run %d: %.1f s/frame" % (done, k + 1, wall / TWIST_FRAMES),
              file=sys.stderr, flush=True)
    with open(os.path.join(d, "summary.json")) as f:
        tri = json.load(f).get("triangles", 0)
    return case_row("twist (%d triangles), frames %d-%d resumed" %
                    (tri, done + 1, done + TWIST_FRAMES), runs, TWIST_FRAMES)


def cg_alone(build, bandwidth):
    """bench_cg_speed on the 200 x 200 sheet at the damped step's half_dt."""
    exe = os.path.join(build, "bench_cg_speed")
    line = subprocess.run([exe, "200", "1e-4", "50"], capture_output=True, text=True,
                          check=True).stdout.strip()
    num = lambda key: float(re.search(key + r" ([0-9.eE+-]+)", line).group(1))
    particles, entries = num("particles"), num("row_entries")
    each_us = float(re.search(r"iterations ([0-9.eE+-]+) us each", line).group(1))
    # bytes one iteration streams (sim/cg.c: an operator pass and an update
    # pass), each array read or written once counted once, as STREAM counts:
    # per row entry its far particle's index (4 B) and direction (3 doubles);
    # the far particle's operand stays in cache (grid neighbours are rows
    # apart). Per particle, the operator pass reads the operand, p, q, z
    # (3 doubles each) and the mass and writes p, q, z; the update pass
    # reads r, q and the 3 x 3 block (6 doubles) and writes r and y: 40
    # doubles, and 3 ints of row bookkeeping.
    bytes_it = entries * 28 + particles * (40 * 8 + 3 * 4)
    gbps = bytes_it / (each_us * 1e-6) / 1e9
    return line, bytes_it, gbps, (gbps / bandwidth if bandwidth else None)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", default="drape20k,drape80k,twist,cg")
    ap.add_argument("--twist-state", help="run folder of the twist at its tangled frame")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "paper_scale"))
    a = ap.parse_args()
    exe = os.path.join(a.build, "clothsim")
    if not os.access(exe, os.X_OK):
        die("no %s: build first" % exe)
    if a.repeat < 1:
        die("--repeat must be >= 1")
    only = set(a.only.split(","))
    unknown = only - {"drape20k", "drape80k", "twist", "twist0", "cg"}
    if unknown:
        die("--only: unknown %s" % ", ".join(sorted(unknown)))
    if "twist" in only and a.twist_state and not os.path.isfile(
            os.path.join(a.twist_state, "state.h5")):
        die("--twist-state %s: not a run folder with a state to resume" % a.twist_state)
    os.makedirs(a.out, exist_ok=True)
    start = cpu_times()
    rows = []
    if "drape20k" in only:
        rows.append(drape(exe, 100, 0, a.repeat, a.out))
    if "drape80k" in only:
        rows.append(drape(exe, 200, 0.002, a.repeat, a.out))
    if "twist0" in only:
        rows.append(twist_from_rest(exe, a.repeat, a.out))
    if "twist" in only:
        if a.twist_state:
            rows.append(twist(exe, a.twist_state, a.repeat, a.out))
        else:
            print("  twist: skipped (no --twist-state; the docstring says how to make it)",
                  file=sys.stderr)
    end = cpu_times()
    md = ["machine: %s" % machine()]
    if start and end and end[1] > start[1]:
        md[0] += "; steal time %.1f%%" % (100.0 * (end[0] - start[0]) / (end[1] - start[1]))
    md += ["", "| case | s/frame (median of N; min-max) | steps/frame | CG it./step | peak MiB "
           "| max intersecting pairs (frames checked) |", "|---|---|---|---|---|---|"]
    for r in rows:
        md.append("| %s | %.3f (%.3f-%.3f), N=%d | %.0f | %.1f | %.0f | %s (%d) |" % (
            r["case"], r["s_per_frame"], r["min"], r["max"], r["runs"], r["steps_per_frame"],
            r["cg_per_step"], r["peak_mib"], r["max_pairs"], r["frames_checked"]))
    if "cg" in only:
        bw = triad(a.build)
        line, bytes_it, gbps, frac = cg_alone(a.build, bw)
        md += ["", "CG alone: " + line,
               "one iteration streams %.1f MB (model): %.1f GB/s%s" % (
                   bytes_it / 1e6, gbps,
                   "; STREAM triad %.1f GB/s, so %.0f%% of it" % (bw, 100 * frac) if bw else "")]
    text = "\n".join(md) + "\n"
    with open(os.path.join(a.out, "paper_scale.md"), "w") as f:
        f.write(text)
    print(text)
    bad = [r["case"] for r in rows if r["max_pairs"]]
    if bad:
        die("intersecting pairs at a frame's end: " + ", ".join(bad))


if __name__ == "__main__":
    main()
