#!/usr/bin/env python3
"""Plots Google Benchmark results (--benchmark_format=json) as an SVG line chart, standard library only.

    build/bin/bench-step --benchmark_filter='contacts:' --benchmark_format=json > step.json
    tools/perfplot/bench_svg.py step.json --filter 'contacts:' --x contacts \
        --goal 1000 --goal-label '1 ms' -o docs/img/step_contacts.svg

x: a counter of each benchmark (default `contacts`); y: its real time per iteration in µs (or --y COUNTER,
several allowed: one line each). --table prints a Markdown table of the same rows on stdout.

Several families in one file (bench-balance: method × edges per cone):

    tools/perfplot/bench_svg.py docs/balance_bench.json --x contacts --time cpu --logy \
        --series '^BM_(\w+)/.*edges:(\d+)' --series-label '\1, \2 edges' \
        --goal-point '20,250,≤ 250 µs' -o docs/balance_bench.svg \
        --pivot --rows 5,10,20,40 --ratio StaticBalanceGenericQp/StaticBalance='generic / static'

--series REGEX: rows whose names give the same capture groups make one line, labelled by --series-label
(a regex template, default the groups joined); the first group picks the colour, the second the dash.
--logy: a logarithmic y axis. --goal-point X,Y,LABEL (repeatable): a target marked at one point (a bar and
a ▼: at most Y there). --pivot prints a Markdown table instead, one row per x (and second group), one
column per first group, --ratio NUM/DEN adding NUM's time over DEN's (the same run's rows). --name
GROUP=TEXT shows a first group's value as TEXT in the legend and the table.
"""
import argparse
import json
import math
import re
import sys

UNIT_TO_US = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}
COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"]
DASHES = ["", "7,4", "2,3", "10,3,2,3"]


def load(path, pattern, xkey, ykeys, time_key="real_time"):
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
            row[y] = b[time_key] * UNIT_TO_US[b.get("time_unit", "ns")] if y == "time" else float(b[y])
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


def series_of(rows, pattern, label, names=None):
    """Groups rows into lines by the capture groups of `pattern` on their names (in order of appearance)."""
    rx = re.compile(pattern)
    if rx.groups < 1:
        sys.exit(f"--series {pattern!r}: needs at least one capture group")
    lines = {}
    for r in rows:
        m = rx.search(r["name"])
        if not m:
            sys.exit(f"--series {pattern!r}: does not match benchmark {r['name']}")
        g = tuple(names.get(x, x) if names and i == 0 else x for i, x in enumerate(m.groups()))
        if g not in lines:
            text = m.expand(label) if label else " ".join(x or "" for x in m.groups())
            if names and m.group(1) in names:  # the display name in the label too
                text = text.replace(m.group(1), names[m.group(1)], 1)
            lines[g] = {"groups": g, "label": text, "rows": []}
        lines[g]["rows"].append(r)
    return list(lines.values())


def fmt_us(v):
    if v >= 1e6:
        return f"{v / 1e6:g} s"
    if v >= 1e3:
        return f"{v / 1e3:g} ms"
    return f"{v:g} µs"


def ticks125(lo_v, hi_v):
    """The 1-2-5 values spanning [lo_v, hi_v]: from the largest at or below lo_v to the smallest at or above hi_v."""
    vals = [m * 10.0 ** d for d in range(math.floor(math.log10(lo_v)) - 1, math.ceil(math.log10(hi_v)) + 1)
            for m in (1, 2, 5)]
    lo = max(v for v in vals if v <= lo_v * (1 + 1e-9))
    hi = min(v for v in vals if v >= hi_v * (1 - 1e-9))
    return [v for v in vals if lo <= v <= hi]


def svg_series(lines, y, xlabel, ylabel, title, logy, goals, goal_points):
    """One line per series, coloured by its first group, dashed by its second; legend on the right."""
    tick = fmt_us if y == "time" else (lambda v: f"{v:g}")
    legend = [s["label"] for s in lines] + [label for _, _, label in goal_points]
    H, L, R, T, B = 480, 70, 20, 40, 50
    LEG = 64 + int(6.0 * max(len(t) for t in legend))
    W = 640 + LEG
    pr = W - R - LEG  # the plot's right edge
    allv = [r[y] for s in lines for r in s["rows"]] + [g[0] for g in goals] + [g[1] for g in goal_points]
    xdata = max([r["x"] for s in lines for r in s["rows"]] + [g[0] for g in goal_points])
    xstep = min(m * 10 ** d for d in range(-3, 10) for m in (1, 2, 5) if xdata / (m * 10 ** d) <= 8)
    xmax = math.ceil(xdata / xstep - 1e-9) * xstep
    if logy:
        if min(allv) <= 0:
            sys.exit("--logy: a value is not positive")
        yvals = ticks125(min(allv), max(allv))
        lo, hi = math.log10(yvals[0]), math.log10(yvals[-1])
        py = lambda v: H - B - (H - T - B) * (math.log10(v) - lo) / (hi - lo)
        yticks = [(v, abs(math.log10(v) - round(math.log10(v))) < 1e-9) for v in yvals]
    else:
        ymax = nice_max(max(allv) * 1.05)
        py = lambda v: H - B - (H - T - B) * v / ymax
        yticks = [(ymax * i / 5, True) for i in range(6)]
    px = lambda x: L + (pr - 16 - L) * x / xmax  # 16 px inside the frame: a goal at xmax stays clear of it
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
           f'<rect width="{W}" height="{H}" fill="white"/>',
           f'<text x="{(L + pr) / 2}" y="22" text-anchor="middle" font-size="15">{title}</text>']
    for v, major in yticks:
        out.append(f'<line x1="{L}" y1="{py(v):.1f}" x2="{pr}" y2="{py(v):.1f}" stroke="{"#ccc" if major else "#eee"}"/>')
        small = "" if major else ' font-size="10" fill="#666"'
        out.append(f'<text x="{L - 6}" y="{py(v) + 4:.1f}" text-anchor="end"{small}>{tick(v)}</text>')
    for i in range(round(xmax / xstep) + 1):
        xv = xstep * i
        out.append(f'<line x1="{px(xv):.1f}" y1="{T}" x2="{px(xv):.1f}" y2="{H - B}" stroke="#eee"/>')
        out.append(f'<text x="{px(xv):.1f}" y="{H - B + 16}" text-anchor="middle">{xv:g}</text>')
    out.append(f'<rect x="{L}" y="{T}" width="{pr - L}" height="{H - T - B}" fill="none" stroke="#333"/>')
    out.append(f'<text x="{(L + pr) / 2}" y="{H - 12}" text-anchor="middle">{xlabel}</text>')
    out.append(f'<text transform="translate(16,{(T + H - B) / 2}) rotate(-90)" text-anchor="middle">{ylabel}</text>')
    for g, label in goals:
        out.append(f'<line x1="{L}" y1="{py(g):.1f}" x2="{pr}" y2="{py(g):.1f}" stroke="#888" stroke-dasharray="6,4"/>')
        out.append(f'<text x="{pr - 4}" y="{py(g) - 5:.1f}" text-anchor="end" fill="#555">{label}</text>')
    firsts = list(dict.fromkeys(s["groups"][0] for s in lines))
    seconds = list(dict.fromkeys(s["groups"][1] for s in lines if len(s["groups"]) > 1))
    for k, s in enumerate(lines):
        c = COLORS[firsts.index(s["groups"][0]) % len(COLORS)]
        d = DASHES[seconds.index(s["groups"][1]) % len(DASHES)] if len(s["groups"]) > 1 else ""
        dash = f' stroke-dasharray="{d}"' if d else ""
        rs = sorted(s["rows"], key=lambda r: r["x"])
        pts = " ".join(f"{px(r['x']):.1f},{py(r[y]):.1f}" for r in rs)
        out.append(f'<polyline points="{pts}" fill="none" stroke="{c}" stroke-width="1.8"{dash}/>')
        out += [f'<circle cx="{px(r["x"]):.1f}" cy="{py(r[y]):.1f}" r="2.5" fill="{c}"><title>{r["name"]}: {r[y]:.1f}</title></circle>'
                for r in rs]
        ly = T + 8 + 17 * k
        out.append(f'<line x1="{pr + 12}" y1="{ly:.1f}" x2="{pr + 42}" y2="{ly:.1f}" stroke="{c}" stroke-width="1.8"{dash}/>')
        out.append(f'<text x="{pr + 48}" y="{ly + 4:.1f}">{s["label"]}</text>')

    def target(x, yy):  # a bar at the target and a ▼ under it: at most this
        return [f'<line x1="{x - 14:.1f}" y1="{yy:.1f}" x2="{x + 14:.1f}" y2="{yy:.1f}" stroke="black" stroke-width="2.5"/>',
                f'<path d="M{x - 5:.1f},{yy + 3:.1f} L{x + 5:.1f},{yy + 3:.1f} L{x:.1f},{yy + 11:.1f} Z" fill="black"/>']

    for k, (gx, gy, label) in enumerate(goal_points):
        x, yy = px(gx), py(gy)
        out += target(x, yy)
        out.append(f'<text x="{x - 18:.1f}" y="{yy + 4:.1f}" text-anchor="end" font-weight="bold" '
                   f'stroke="white" stroke-width="3" paint-order="stroke">{"≤ " + tick(gy)}</text>')
        ly = T + 8 + 17 * (len(lines) + k) + 8
        out += target(pr + 27, ly - 4)
        out.append(f'<text x="{pr + 48}" y="{ly + 4:.1f}">{label}</text>')
    out.append("</svg>")
    return "\n".join(out) + "\n"


def pivot(lines, y, rows_x, ratios, row_head):
    """Markdown: one row per (x, second group), one column per first group, then the ratios."""
    firsts = list(dict.fromkeys(s["groups"][0] for s in lines))
    cell = {}
    for s in lines:
        for r in s["rows"]:
            cell[(r["x"], s["groups"][1:], s["groups"][0])] = r[y]
    keys = sorted({(x, rest) for (x, rest, _) in cell}, key=lambda k: (k[1], k[0]))
    if rows_x:
        keys = [k for k in keys if k[0] in rows_x]
    for num, den, _ in ratios:
        for n in (num, den):
            if n not in firsts:
                sys.exit(f"--ratio: no series {n!r} (series: {', '.join(firsts)})")
    head = [row_head] + firsts + [h for _, _, h in ratios]
    print("| " + " | ".join(head) + " |")
    print("|---|" + "---:|" * (len(head) - 1))
    for x, rest in keys:
        vals = [cell.get((x, rest, f)) for f in firsts]
        rat = [cell.get((x, rest, n)) / cell[(x, rest, d)] if cell.get((x, rest, n)) and cell.get((x, rest, d)) else None
               for n, d, _ in ratios]
        print(f"| {x:g}{' × ' + ' '.join(rest) if rest else ''} | " +
              " | ".join("" if v is None else f"{v:.0f}" for v in vals) +
              "".join(" | " + ("" if v is None else f"{v:.1f}") for v in rat) + " |")


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
    ap.add_argument("--time", choices=["real", "cpu"], default="real", help="which time is 'time' (default real)")
    ap.add_argument("--series", help="regex with capture groups on the names: one line per distinct groups")
    ap.add_argument("--series-label", help="a regex template (\\1, \\2) naming a series' line")
    ap.add_argument("--name", action="append", default=[], metavar="GROUP=TEXT",
                    help="with --series: show a first group's value as TEXT (legend, table; repeatable)")
    ap.add_argument("--logy", action="store_true", help="logarithmic y axis (with --series)")
    ap.add_argument("--goal-point", action="append", default=[], metavar="X,Y,LABEL",
                    help="a target at one point: at most Y at X (with --series; repeatable)")
    ap.add_argument("--pivot", action="store_true", help="with --series: a Markdown table, x by series")
    ap.add_argument("--rows", help="with --pivot: only these x values (comma-separated)")
    ap.add_argument("--ratio", action="append", default=[], metavar="NUM/DEN[=HEADER]",
                    help="with --pivot: a column of series NUM's value over DEN's (first groups; repeatable)")
    ap.add_argument("--row-head", help="with --pivot: the first column's heading (default the --x counter)")
    ap.add_argument("-o", "--out", help="SVG file")
    a = ap.parse_args()
    ykeys = a.y or ["time"]
    rows = load(a.json, a.filter, a.x, ykeys, f"{a.time}_time")
    if a.series:
        if len(ykeys) != 1:
            sys.exit("--series: one --y only")
        goal_points = []
        for g in a.goal_point:
            parts = g.split(",", 2)
            try:
                goal_points.append((float(parts[0]), float(parts[1]), parts[2] if len(parts) > 2 else ""))
            except (ValueError, IndexError):
                sys.exit(f"--goal-point {g!r}: expected X,Y,LABEL")
        names = {}
        for n in a.name:
            if "=" not in n:
                sys.exit(f"--name {n!r}: expected GROUP=TEXT")
            k, v = n.split("=", 1)
            names[k] = v
        lines = series_of(rows, a.series, a.series_label, names)
        ratios = []  # (num, den, header), num and den first groups (benchmark names), shown by --name
        for r in a.ratio:
            spec, _, head = r.partition("=")
            if spec.count("/") != 1:
                sys.exit(f"--ratio {r!r}: expected NUM/DEN[=HEADER]")
            num, den = (names.get(x, x) for x in spec.split("/"))
            ratios.append((num, den, head or f"{num} / {den}"))
        if a.out:
            with open(a.out, "w") as f:
                f.write(svg_series(lines, ykeys[0], a.xlabel, a.ylabel, a.title, a.logy,
                                   [(a.goal, a.goal_label)] if a.goal else [], goal_points))
        if a.pivot:
            pivot(lines, ykeys[0], {float(v) for v in a.rows.split(",")} if a.rows else None, ratios, a.row_head or a.x)
        return
    if a.logy or a.goal_point or a.pivot or a.ratio or a.name:
        sys.exit("--logy, --goal-point, --pivot, --ratio and --name go with --series")
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
