#!/usr/bin/env python3
"""A/B benchmark of two (or more) builds on a noisy host: runs each checkout's build/bin/<bench> in turn,
REPS times, and prints per case the minimum and the median of each build (and of the MuJoCo ratio where
the case reports one). Alternating the builds spreads the host's load over both.

  tools/perfplot/ab_bench.py --filter 'standing|contacts:100$' --reps 5 /path/to/checkout-a /path/to/checkout-b
"""
import argparse
import collections
import json
import statistics
import subprocess
import sys


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bench", default="bench-step", help="executable in build/bin (default bench-step)")
    ap.add_argument("--filter", required=True, help="--benchmark_filter regex")
    ap.add_argument("--reps", type=int, default=5, help="runs per build (default 5)")
    ap.add_argument("checkouts", nargs="+", help="checkouts whose build/bin holds the executable")
    a = ap.parse_args()
    if a.reps < 1:
        print("ab_bench: --reps must be >= 1", file=sys.stderr)
        return 2
    times = collections.defaultdict(lambda: collections.defaultdict(list))
    ratios = collections.defaultdict(lambda: collections.defaultdict(list))
    for _ in range(a.reps):
        for c in a.checkouts:
            exe = f"{c}/build/bin/{a.bench}"
            try:
                run = subprocess.run([exe, f"--benchmark_filter={a.filter}", "--benchmark_format=json"],
                                     capture_output=True, text=True, check=True)
            except (OSError, subprocess.CalledProcessError) as e:
                print(f"ab_bench: {exe}: {e}", file=sys.stderr)
                return 1
            for b in json.loads(run.stdout)["benchmarks"]:
                times[b["name"]][c].append(b.get("ours_us", b["real_time"]))
                if "ratio" in b:
                    ratios[b["name"]][c].append(b["ratio"])
    for name in times:
        for c in a.checkouts:
            v = times[name][c]
            line = f"{name:45s} {c:24s} min {min(v):8.1f} median {statistics.median(v):8.1f}"
            if ratios[name][c]:
                r = ratios[name][c]
                line += f"   ratio min {min(r):.2f} median {statistics.median(r):.2f}"
            print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
