#!/usr/bin/env python3
"""bench/speed.py: speed at resolution, measured the way a user runs.

Runs scenes/bench/sheet_ball.yaml (a 1 m sheet falling on a ball on the
ground) at 50x50, 100x100 and 200x200 quads (5,000, 20,000 and 80,000
triangles; repulsion thickness 8, 4 and 2 mm), 48 frames, with self-collision
on (verifier on: every frame must end with 0 intersecting pairs) and off,
each REPEAT times as one plain `clothsim run` (no launcher, default threads).
Prints per case the median wall seconds per frame over the whole run, steps
and CG iterations per frame, peak memory, intersecting pairs, the stage table
of the median run, a free-fall frame with self-collision against one
without (median over the frames before the first body contact), the
exponent of seconds per frame against triangles, and
for the largest case the inner step's cost in ns per spring per step and as
estimated memory traffic against a STREAM triad measured in the same run.

usage: bench/speed.py [--build DIR] [--repeat N] [--frames N] [--sizes 50,100,200]
                      [--modes on,off] [--step-limit auto|undamped|damped]
                      [--pruning speed|path] [--out DIR]
Writes DIR/speed.csv and DIR/speed.md (default out/speed). Numbers go in
docs/performance.md by hand, with the machine. A Release build is expected.
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SCENE = os.path.join(ROOT, "scenes", "bench", "sheet_ball.yaml")
THICKNESS = {50: 0.008, 100: 0.004, 200: 0.002}
INNER_STAGES = ["scripted_vertices", "wind", "velocity_half", "self_repulsion", "position_update",
                "body_collision", "velocity_full", "body_friction", "self_friction"]


def die(msg):
    sys.exit("speed.py: " + msg)


def timed_run(args, log_dir):
    """Runs args with stdout and stderr into log_dir; dies unless it exits 0.
    Returns (wall seconds, this run's own peak RSS in MiB, stdout)."""
    os.makedirs(log_dir, exist_ok=True)
    log_out, log_err = os.path.join(log_dir, "stdout.txt"), os.path.join(log_dir, "stderr.txt")
    t0 = time.monotonic()
    with open(log_out, "w") as fo, open(log_err, "w") as fe:
        proc = subprocess.Popen(args, stdout=fo, stderr=fe)
        _, status, usage = os.wait4(proc.pid, 0)
    wall = time.monotonic() - t0
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        die("%s exited %d:\n%s" % (" ".join(args), code, open(log_err).read()))
    return wall, usage.ru_maxrss / 1024.0, open(log_out).read()


def run_once(exe, n, selfcol, frames, out, step_limit, pruning):
    """One whole run; returns (wall seconds, peak RSS MiB, summary, stage table text)."""
    thick = THICKNESS.get(n, 0.4 / n)
    args = [exe, "run", SCENE, "-o", out, "-q", "--frames", str(frames),
            "--set", "cloths.0.grid.resolution=[%d,%d]" % (n, n),
            "--set", "self_collision.thickness=%g" % thick,
            "--set", "time.step_limit=" + step_limit,
            "--set", "self_collision.pruning=" + pruning]
    if not selfcol:
        args += ["--set", "effects.self_collision=false"]
    wall, rss, stdout = timed_run(args, out)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    table = "\n".join(l for l in stdout.splitlines()
                      if l[:1].isalpha() or l.startswith("all stages") or l.startswith("stage"))
    return wall, rss, summary, table


def triad(build):
    exe = os.path.join(build, "bench_stream_triad")
    if not os.access(exe, os.X_OK):
        return None
    out = subprocess.run([exe], capture_output=True, text=True, check=True).stdout.split()
    return float(out[1])


def machine():
    """The CPU model, its count and caches (lscpu), for docs/performance.md's "with the machine"."""
    model = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            model = next((l.split(":", 1)[1].strip() for l in f if l.startswith("model name")), model)
    except OSError:
        pass
    caches = []
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=False).stdout
        caches = [l.split(":", 1)[0].strip() + " " + l.split(":", 1)[1].strip()
                  for l in out.splitlines() if l.startswith(("L2 cache", "L3 cache"))]
    except OSError:
        pass
    return ", ".join([model, "%d CPUs" % os.cpu_count()] + caches)


def cpu_times():
    """(steal, total) jiffies of all CPUs from /proc/stat, or None"""
    try:
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:]]
        return v[7] if len(v) > 7 else 0, sum(v[:8])
    except (OSError, ValueError):
        return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--frames", type=int, default=48)
    ap.add_argument("--sizes", default="50,100,200")
    ap.add_argument("--modes", default="on,off")
    ap.add_argument("--step-limit", default="auto", choices=["auto", "undamped", "damped"],
                    help="time.step_limit for every run (auto, the default, as the scene)")
    ap.add_argument("--pruning", default="speed", choices=["speed", "path"],
                    help="self_collision.pruning for every run (the scene's default is speed)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "speed"))
    a = ap.parse_args()
    exe = os.path.join(a.build, "clothsim")
    if not os.access(exe, os.X_OK):
        die("no %s: build first (scripts/main.sh builds build/)" % exe)
    if a.repeat < 1 or a.frames < 1:
        die("--repeat and --frames must be >= 1")
    sizes = [int(s) for s in a.sizes.split(",")]
    modes = [m == "on" for m in a.modes.split(",")]
    os.makedirs(a.out, exist_ok=True)
    bw = triad(a.build)
    start_times = cpu_times()
    rows, tables = [], []
    for selfcol in modes:
        for n in sizes:
            runs = []
            for rep in range(a.repeat):
                runs.append(run_once(exe, n, selfcol, a.frames,
                                     os.path.join(a.out, "run_%d_%s" % (n, "on" if selfcol else "off")),
                                     a.step_limit, a.pruning))
                print("  %dx%d self-collision %s, run %d: %.3f s/frame" %
                      (n, n, "on" if selfcol else "off", rep + 1, runs[-1][0] / a.frames),
                      file=sys.stderr, flush=True)
            runs.sort(key=lambda x: x[0])
            wall, rss, s, table = runs[len(runs) // 2]
            frames = s["frames"][1:] if s["frames"] and s["frames"][0].get("steps", 1) == 0 else s["frames"]
            inter = [f.get("intersections") for f in frames if f.get("intersections") is not None]
            steps = sum(f.get("steps", 0) for f in frames)
            cg = sum(f.get("cg_iterations", 0) for f in frames)
            # free fall: the frames before the cloth first touches a body
            first_contact = next((k for k, f in enumerate(frames) if f.get("body_contacts", 0) > 0),
                                 len(frames))
            free_fall = [f["seconds"] for f in frames[:first_contact] if "seconds" in f]
            stages = {st["name"]: st["seconds"] for st in s.get("stages", [])}
            inner = sum(stages.get(k, 0) for k in INNER_STAGES)
            springs = s.get("springs", 0)
            row = {
                "quads": n, "triangles": s["triangles"], "particles": s["particles"],
                "springs": springs, "self_collision": "on" if selfcol else "off",
                "threads": s.get("threads", 1),
                "seconds_per_frame": statistics.median(x[0] for x in runs) / a.frames,
                "min_s_per_frame": runs[0][0] / a.frames, "max_s_per_frame": runs[-1][0] / a.frames,
                "steps_per_frame": steps / max(len(frames), 1),
                "cg_per_frame": cg / max(len(frames), 1),
                "peak_mib": max(x[1] for x in runs),
                "free_fall_s_per_frame": statistics.median(free_fall) if free_fall else 0.0,
                "free_fall_frames": len(free_fall),
                "max_intersections": max(inter) if inter else "",
                "frames_checked": len(inter),
                "ns_per_spring_step": 1e9 * inner / max(steps * springs, 1),
            }
            # traffic model of one step, if every byte came from memory
            # (sim/springs.c, sim/cg.c; update it when their passes change): every spring is an
            # entry in both its ends' rows. The prepare pass (twice a step)
            # reads an entry's far end (4 B) and 3 constants (24 B) and
            # writes its direction (24 B) and magnitude (8 B): 120 B per
            # spring. A damping pass reads far end and direction: 56 B per
            # spring; a step makes 2 CG setup passes, 1 for v_NP and one
            # per CG iteration. CG's vectors: about 13 arrays of 24 B per
            # particle per iteration, and 28 per step for the rest.
            it_step = cg / max(steps, 1)
            bytes_step = springs * (2 * 120 + 56 * (3 + it_step)) + \
                s["particles"] * 24 * (28 + 13 * it_step)
            row["model_GBps"] = bytes_step * steps / inner / 1e9 if inner > 0 else 0
            row["triad_GBps"] = bw or 0
            rows.append(row)
            tables.append("%dx%d, self-collision %s (median run):\n%s" %
                          (n, n, row["self_collision"], table))
    fields = list(rows[0].keys())
    with open(os.path.join(a.out, "speed.csv"), "w") as f:
        f.write(",".join(fields) + "\n")
        for r in rows:
            f.write(",".join(("%.6g" % v) if isinstance(v, float) else str(v) for v in r.values()) + "\n")
    end_times = cpu_times()
    # a VM's steal time (its host running others on our CPUs) makes whole
    # runs of one binary differ by up to 2x: say how much there was
    steal = ""
    if start_times and end_times and end_times[1] > start_times[1]:
        steal = "; steal time during the runs %.1f%%" % (
            100.0 * (end_times[0] - start_times[0]) / (end_times[1] - start_times[1]))
    md = ["machine: %s%s\n" % (machine(), steal),
          "| quads | triangles | self-collision | threads | s/frame (median of %d; min-max) | steps/frame | CG it./frame | peak MiB | max intersecting pairs (frames) | ns/spring/step |" % a.repeat,
          "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        md.append("| %d | %d | %s | %d | %.3f (%.3f-%.3f) | %.0f | %.0f | %.0f | %s (%d) | %.2f |" % (
            r["quads"], r["triangles"], r["self_collision"], r["threads"], r["seconds_per_frame"],
            r["min_s_per_frame"], r["max_s_per_frame"], r["steps_per_frame"], r["cg_per_frame"],
            r["peak_mib"], r["max_intersections"], r["frames_checked"], r["ns_per_spring_step"]))
    for mode in ("on", "off"):
        pts = [(r["triangles"], r["seconds_per_frame"]) for r in rows if r["self_collision"] == mode]
        if len(pts) >= 2:
            xs = [math.log(p[0]) for p in pts]
            ys = [math.log(p[1]) for p in pts]
            mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
            slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
            md.append("\nself-collision %s: seconds per frame ~ triangles^%.2f "
                      "(explicit elastic forces: steps ~ edge length^-1.5 ~ triangles^0.75, "
                      "work per step ~ triangles, so 1.75 expected)" % (mode, slope))
    for n in sizes:
        on = [r for r in rows if r["quads"] == n and r["self_collision"] == "on"]
        off = [r for r in rows if r["quads"] == n and r["self_collision"] == "off"]
        if on and off and on[0]["free_fall_frames"] and off[0]["free_fall_frames"]:
            md.append("\n%dx%d: a free-fall frame (median over the %d frames before the first body "
                      "contact) costs %.3f s with self-collision and %.3f s without: %.2f times "
                      "(the target: at most 1.3)" % (
                          n, n, on[0]["free_fall_frames"], on[0]["free_fall_s_per_frame"],
                          off[0]["free_fall_s_per_frame"],
                          on[0]["free_fall_s_per_frame"] / off[0]["free_fall_s_per_frame"]))
    big = max(rows, key=lambda r: (r["triangles"], r["self_collision"] == "on"))
    if bw:
        md.append("\n%dx%d: inner step %.2f ns per spring per step; modelled traffic %.1f GB/s "
                  "against a STREAM triad of %.1f GB/s (%.0f%%) on %d threads" % (
                      big["quads"], big["quads"], big["ns_per_spring_step"], big["model_GBps"],
                      bw, 100 * big["model_GBps"] / bw, big["threads"]))
    text = "\n".join(md) + "\n\n" + "\n\n".join(tables) + "\n"
    with open(os.path.join(a.out, "speed.md"), "w") as f:
        f.write(text)
    print(text)
    bad = [r for r in rows if r["self_collision"] == "on" and r["max_intersections"] not in ("", 0)]
    if bad:
        die("intersecting pairs at a frame end: %s" % ", ".join("%dx%d" % (r["quads"], r["quads"]) for r in bad))


if __name__ == "__main__":
    main()
