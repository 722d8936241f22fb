#!/usr/bin/env python3
"""Plots Google Benchmark results (--benchmark_format=json) as an SVG line chart, standard library only.

    build/bin/bench-step --benchmark_filter='contacts:' --benchmark_format=json > step.json
    tools/perfplot/bench_svg.py step.json --filter 'contacts:' --x contacts \
        --goal 1000 --goal-label '1 ms' -o docs/img/step_contacts.svg

x: a counter of each benchmark (default `contacts`); y: its real time per iteration in µs (or --y COUNTER,
several allowed: one line each). --table prints a Markdown table of the same rows on stdout.
"""
import argparse
import json
import math
import re
import sys

UNIT_TO_US = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}
COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"]


def load(path, pattern, xkey, ykeys):
    with open(path) as f:
        data = json.load(f)
    rows = []
    for b in data.get("benchmarks", []):
        if b.get("run_type", "iteration") != "iteration" or not re.search(pattern, b["name"]):
            continue
        if xkey not in b:
            sys.exit(f"{path}: benchmark {b['name']} has no counter '{xkey}'")
        row = {"name": b["name"], "x": float(b[xkey]), "b": b}
        for y in ykeys:
            row[y] = b["real_time"] * UNIT_TO_US[b.get("time_unit", "ns")] if y == "time" else float(b[y])
        rows.append(row)
    if not rows:
        sys.exit(f"{path}: no benchmark matches '{pattern}'")
    return sorted(rows, key=lambda r: r["x"])


def nice_max(v):
    if v <= 0:
        return 1.0
    e = 10 ** math.floor(math.log10(v))
    for m in (1, 2, 2.5, 5, 10):
        if m * e >= v:
            return m * e
    return 10 * e


def svg(rows, ykeys, xlabel, ylabel, title, goal, goal_label):
    W, H, L, R, T, B = 720, 420, 70, 20, 40, 50
    xmax = nice_max(max(r["x"] for r in rows))
    ymax = nice_max(max([max(r[y] for r in rows) for y in ykeys] + ([goal * 1.1] if goal else [])))
    px = lambda x: L + (W - L - R) * x / xmax
    py = lambda y: H - B - (H - T - B) * y / ymax
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
           f'<rect width="{W}" height="{H}" fill="white"/>',
           f'<text x="{W / 2}" y="22" text-anchor="middle" font-size="15">{title}</text>']
    for i in range(6):  # grid and ticks
        yv, xv = ymax * i / 5, xmax * i / 5
        out.append(f'<line x1="{L}" y1="{py(yv):.1f}" x2="{W - R}" y2="{py(yv):.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{L - 6}" y="{py(yv) + 4:.1f}" text-anchor="end">{yv:g}</text>')
        out.append(f'<line x1="{px(xv):.1f}" y1="{T}" x2="{px(xv):.1f}" y2="{H - B}" stroke="#eee"/>')
        out.append(f'<text x="{px(xv):.1f}" y="{H - B + 16}" text-anchor="middle">{xv:g}</text>')
    out.append(f'<rect x="{L}" y="{T}" width="{W - L - R}" height="{H - T - B}" fill="none" stroke="#333"/>')
    out.append(f'<text x="{(L + W - R) / 2}" y="{H - 12}" text-anchor="middle">{xlabel}</text>')
    out.append(f'<text transform="translate(16,{(T + H - B) / 2}) rotate(-90)" text-anchor="middle">{ylabel}</text>')
    if goal:
        out.append(f'<line x1="{L}" y1="{py(goal):.1f}" x2="{W - R}" y2="{py(goal):.1f}" stroke="#888" stroke-dasharray="6,4"/>')
        out.append(f'<text x="{W - R - 4}" y="{py(goal) - 5:.1f}" text-anchor="end" fill="#555">{goal_label}</text>')
    for k, y in enumerate(ykeys):
        c = COLORS[k % len(COLORS)]
        pts = " ".join(f"{px(r['x']):.1f},{py(r[y]):.1f}" for r in rows)
        out.append(f'<polyline points="{pts}" fill="none" stroke="{c}" stroke-width="2"/>')
        out += [f'<circle cx="{px(r["x"]):.1f}" cy="{py(r[y]):.1f}" r="3" fill="{c}"><title>{r["name"]}: {r[y]:.1f}</title></circle>'
                for r in rows]
        out.append(f'<text x="{L + 10}" y="{T + 16 + 16 * k}" fill="{c}">{"time per step (µs)" if y == "time" else y}</text>')
    out.append("</svg>")
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("json")
    ap.add_argument("--filter", default=".", help="regex on benchmark names")
    ap.add_argument("--x", default="contacts", help="counter on the x axis")
    ap.add_argument("--y", action="append", help="'time' (µs per iteration, default) or counters")
    ap.add_argument("--xlabel", default="contact rows (measured mean)")
    ap.add_argument("--ylabel", default="µs per World step")
    ap.add_argument("--title", default="bench-step: World step with physics vs contact rows")
    ap.add_argument("--goal", type=float, default=None, help="a horizontal goal line (y units)")
    ap.add_argument("--goal-label", default="goal")
    ap.add_argument("--table", action="store_true", help="print a Markdown table on stdout")
    ap.add_argument("-o", "--out", help="SVG file")
    a = ap.parse_args()
    ykeys = a.y or ["time"]
    rows = load(a.json, a.filter, a.x, ykeys)
    if a.out:
        with open(a.out, "w") as f:
            f.write(svg(rows, ykeys, a.xlabel, a.ylabel, a.title, a.goal, a.goal_label))
    if a.table:
        counters = ["contacts", "active", "lcp", "pivots", "collision_us", "constraints_us", "integrate_us", "max_pen_mm",
                    "lcp_failures"]
        print("| case | µs/step | " + " | ".join(counters) + " |")
        print("|---|---:|" + "---:|" * len(counters))
        for r in rows:
            b = r["b"]
            t = b["real_time"] * UNIT_TO_US[b.get("time_unit", "ns")]
            print(f"| `{r['name'].split('/', 1)[-1]}` | {t:.0f} | " +
                  " | ".join(f"{b[c]:.3g}" if c in b else "" for c in counters) + " |")


if __name__ == "__main__":
    main()
