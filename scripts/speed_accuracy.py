#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
"""Turns bench_tradeoff's JSON output into the generated part of docs/speed-accuracy.md and one PNG per scene.

    build/bench/bench_tradeoff --benchmark_format=json --benchmark_out=tradeoff.json
    python3 scripts/speed_accuracy.py tradeoff.json [more.json ...] [--doc docs/speed-accuracy.md]

Several JSON files (e.g. runs of different scenes with --benchmark_filter) are merged.

The Markdown file keeps everything outside the markers <!-- BEGIN GENERATED --> / <!-- END GENERATED -->; the
tables, Pareto fronts and plot links between them are rewritten. Plots need gnuplot (Debian: gnuplot-nox,
`bash scripts/install-deps.sh --with-plot`); without it the tables are still written.
"""
import json
import os
import re
import shutil
import subprocess
import sys

# Error above which a setting no longer does the scene's job (the "usable" line of the report), with its meaning.
USABLE = {
    "chain20": (0.01, "largest joint separation over 5 s, m; usable below 1 cm"),
    "tower10": (0.01, "largest box displacement after 3 s, m; usable below 1 cm (docs/scenes.md goal)"),
    "pyramid20": (0.1, "largest box displacement after 3 s, m; usable below 10 cm (the stand test)"),
    "mass_ratio": (0.01, "worst overlap of the two boxes over 3 s, m (1000 = light box squeezed out); usable below 1 cm"),
    "pile1000": (0.005, "largest penetration after 2 s, m; usable below 5 mm (10 % of the radius)"),
}
ORDER = ["chain20", "tower10", "pyramid20", "mass_ratio", "pile1000"]
RATES = [30, 60, 120, 240]


def load(path):
    with open(path) as f:
        data = json.load(f)
    rows = []
    for b in data["benchmarks"]:
        m = re.match(r"([^/]+)/([A-Z]+)/it:(\d+)/dt:1_(\d+)", b["name"])
        if not m:
            continue
        rows.append(dict(scene=m.group(1), type=m.group(2), it=int(m.group(3)), rate=int(m.group(4)),
                         ms=b["ms_per_step"], cost=b["ms_per_sim_s"], error=b["error"], finite=b["finite"] > 0))
    return rows


def label(r):
    return "DIRECT" if r["type"] == "DIRECT" else "%s %d" % (r["type"], r["it"])


def fmt_err(e):
    if e >= 1e299:
        return "inf"
    return "%.2g" % e


def usable(r):
    return r["finite"] and r["error"] < USABLE[r["scene"]][0]


def pareto(rows):
    # Cheapest first; a point joins the front when it cuts the best error so far by more than 10 % (smaller
    # differences are within the run-to-run scatter of the error and of the timing).
    front, best = [], float("inf")
    for r in sorted(rows, key=lambda r: (r["cost"], r["error"])):
        if r["error"] < 0.9 * best:
            front.append(r)
            best = r["error"]
    return front


def plot(scene, rows, outdir):
    if not shutil.which("gnuplot"):
        return None
    os.makedirs(outdir, exist_ok=True)
    series, files = [], []
    styles = {"PGS": "with points pt 7", "SPLIT": "with points pt 5", "DIRECT": "with points pt 9 ps 1.5",
              "Pareto front": "with lines lw 2"}
    for t in ["PGS", "SPLIT", "DIRECT", "Pareto front"]:
        pts = pareto(rows) if t == "Pareto front" else [r for r in rows if r["type"] == t]
        if not pts:
            continue
        dat = os.path.join(outdir, "%s.%s.dat" % (scene, t.split()[0]))
        with open(dat, "w") as f:
            for r in pts:
                f.write("%g %g\n" % (r["cost"], max(min(r["error"], 1e3), 1e-9)))
        files.append(dat)
        series.append("'%s' %s title '%s'" % (dat, styles[t], t))
    png = os.path.join(outdir, scene + ".png")
    limit = USABLE[scene][0]
    script = f"""
set terminal png size 800,520
set output '{png}'
set logscale xy
set xlabel 'wall time per simulated second (ms)'
set ylabel 'error (m)'
set title '{scene}: error against cost (dt 1/30 .. 1/240, 5 .. 200 iterations)'
set key outside right
set arrow from graph 0, first {limit} to graph 1, first {limit} nohead dt 2
plot {", ".join(series)}
"""
    subprocess.run(["gnuplot"], input=script, text=True, check=True)
    for dat in files:
        os.remove(dat)
    return png


def generate(rows, docdir):
    out = []
    for scene in ORDER:
        srows = [r for r in rows if r["scene"] == scene]
        if not srows:
            continue
        limit, meaning = USABLE[scene]
        out.append("### %s\n\nError: %s. Cells: median ms per step · error; **bold** = usable, ✗ = not usable.\n"
                   % (scene, meaning))
        configs = []
        for r in srows:
            if label(r) not in configs:
                configs.append(label(r))
        out.append("| solver | " + " | ".join("dt 1/%d" % k for k in RATES) + " |")
        out.append("|---|" + "---|" * len(RATES))
        for c in configs:
            cells = []
            for k in RATES:
                m = [r for r in srows if label(r) == c and r["rate"] == k]
                if not m:
                    cells.append("")
                    continue
                r = m[0]
                e = fmt_err(r["error"]) if r["finite"] else "non-finite"
                cells.append(("%.3g · **%s**" if usable(r) else "%.3g · %s ✗") % (r["ms"], e))
            out.append("| %s | %s |" % (c, " | ".join(cells)))
        front = pareto(srows)
        out.append("\nPareto front (wall time per simulated second → error):\n")
        for r in front:
            out.append("- %s at dt 1/%d: %.3g ms per simulated s, error %s%s" %
                       (label(r), r["rate"], r["cost"], fmt_err(r["error"]), "" if usable(r) else " (not usable)"))
        cheapest = [r for r in sorted(srows, key=lambda r: r["cost"]) if usable(r)]
        if cheapest:
            r = cheapest[0]
            out.append("\nCheapest usable setting: **%s at dt 1/%d** (%.3g ms per simulated s, error %s)." %
                       (label(r), r["rate"], r["cost"], fmt_err(r["error"])))
        else:
            out.append("\nNo setting of the sweep is usable on this scene.")
        png = plot(scene, srows, os.path.join(docdir, "speed-accuracy"))
        if png:
            out.append("\n![%s](speed-accuracy/%s.png)\n" % (scene, scene))
        out.append("")
    return "\n".join(out)


def main():
    args = sys.argv[1:]
    doc = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs", "speed-accuracy.md")
    if "--doc" in args:
        i = args.index("--doc")
        doc = args[i + 1]
        del args[i:i + 2]
    rows = []
    for src in args:
        rows += load(src)
    body = generate(rows, os.path.dirname(os.path.abspath(doc)))
    text = open(doc).read() if os.path.exists(doc) else "<!-- BEGIN GENERATED -->\n<!-- END GENERATED -->\n"
    begin, end = "<!-- BEGIN GENERATED -->", "<!-- END GENERATED -->"
    i, j = text.index(begin) + len(begin), text.index(end)
    text = text[:i] + "\n" + body + "\n" + text[j:]
    with open(doc, "w") as f:
        f.write(text)
    print("wrote", doc)


if __name__ == "__main__":
    main()
