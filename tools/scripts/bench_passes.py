#!/usr/bin/env python3
"""Each pass's GPU time, two or more builds of siviflow side by side in one sitting: the figures a
closing note quotes, by one command.

usage: tools/scripts/bench_passes.py [--rounds N] [--size WxH] [--frames F] [--scene SCENE.json]
                                     NAME=BINARY NAME=BINARY ...
  Each round runs `bench --json` once per build, in the order given (alternating, so a machine
  that drifts drifts for all of them); lavapipe with 2 threads, as CI renders. Prints, per build,
  the median and range over the rounds of each run's median: frame - floor (what a user's frame
  costs), the world, the reflection, the flow material, its floor, flow / floor (per run) and the
  water; then each later build's medians over the first's.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

# (label, how a run's figure is read from bench's JSON)
FIGURES = [
    ("frame - floor", lambda r: r["frame_without_floor_ms"]),
    ("world", lambda r: r["passes"]["world"]["median_ms"]),
    ("reflection", lambda r: r["passes"]["reflection"]["median_ms"]),
    ("flow material", lambda r: r["passes"]["flow material"]["median_ms"]),
    ("flow floor", lambda r: r["floor_ms"]),
    ("flow / floor", lambda r: r["passes"]["flow material"]["median_ms"] / r["floor_ms"]),
    ("water", lambda r: r["passes"]["water"]["median_ms"]),
]


def run_bench(name, binary, args):
    """The figures of one `bench --json` run of `binary`."""
    command = [binary, "bench"] + ([args.scene] if args.scene else []) + [
        "--size", args.size, "--frames", str(args.frames), "--json"]
    try:
        done = subprocess.run(command, capture_output=True, text=True)
    except OSError as error:
        sys.exit(f"{name}: cannot run {binary}: {error.strerror}")
    if done.returncode != 0:
        sys.exit(f"{name}: {binary} bench exited {done.returncode}: "
                 + (done.stderr.strip().splitlines() or ["(no message)"])[-1])
    try:
        report = json.loads(done.stdout)
        return [read(report) for _, read in FIGURES]
    except (ValueError, KeyError, TypeError, ZeroDivisionError) as error:
        sys.exit(f"{name}: {binary} bench --json printed no pass times this script reads "
                 f"({type(error).__name__}: {error})")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--scene")
    parser.add_argument("builds", nargs="+", metavar="NAME=BINARY")
    args = parser.parse_args()
    builds = [pair.split("=", 1) for pair in args.builds]
    if any(len(pair) != 2 or not pair[0] for pair in builds):
        sys.exit("each build is NAME=BINARY")
    if len({name for name, _ in builds}) != len(builds):
        sys.exit("two builds share a name")
    if args.rounds < 1 or args.frames < 1:
        sys.exit("--rounds and --frames: 1 or more")
    os.environ.setdefault("VK_DRIVER_FILES", "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json")
    os.environ.setdefault("LP_NUM_THREADS", "2")

    runs = {name: [] for name, _ in builds}  # per build, per round, the figures
    for round_index in range(args.rounds):
        for name, binary in builds:
            runs[name].append(run_bench(name, binary, args))
            print(f"round {round_index + 1}: {name}: " + ", ".join(
                f"{label} {value:.3f}" for (label, _), value in zip(FIGURES, runs[name][-1])),
                flush=True)
    print(f"{args.size}, {args.frames} frames, {args.rounds} alternating rounds: "
          "median (min-max) of the runs' medians, ms")
    medians = {}
    for name, _ in builds:
        columns = list(zip(*runs[name]))
        medians[name] = [statistics.median(column) for column in columns]
        print(f"{name}: " + "; ".join(
            f"{label} {median:.3f} ({min(column):.3f}-{max(column):.3f})"
            for (label, _), median, column in zip(FIGURES, medians[name], columns)))
    first = builds[0][0]
    for name, _ in builds[1:]:
        print(f"{name} / {first}: " + ", ".join(
            f"{label} {mine / theirs:.3f}" for (label, _), mine, theirs
            in zip(FIGURES, medians[name], medians[first]) if theirs > 0))


if __name__ == "__main__":
    main()
