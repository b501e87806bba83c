#!/usr/bin/python3
"""Figures of `rbx bench`: log-log time against size for the narrow phase (one figure per pose
kind, one line per backend and variant) and the broad phase (one line per method), and bars of
microseconds per body per step for the whole step.

Usage: bench_plots.py DIR  (reads DIR/perf.json, writes DIR/figures/perf_*.png and *.svg)
"""
import json
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import backend_style  # noqa: E402

METHOD_STYLE = {"all-pairs": ("tab:red", "o"), "sweep-and-prune": ("tab:orange", "s"),
                "tree": ("tab:blue", "^")}


def narrowphase(rows, out):
    """Time per query against hull vertices, log-log; the box drawn as a separate marker at N=8."""
    by_pose = defaultdict(lambda: defaultdict(list))
    for r in rows:
        if r["kind"] == "narrowphase" and r["ns_per_query"] is not None:
            by_pose[r["pose"]][(r["backend"], r["variant"])].append(
                (r["vertices"], r["ns_per_query"], r.get("q25") or r["ns_per_query"],
                 r.get("q75") or r["ns_per_query"]))
    for pose, series in by_pose.items():
        fig, ax = plt.subplots(figsize=(8, 5.5))
        for (backend, variant), pts in sorted(series.items()):
            pts.sort()
            hull = [(n, t * 1e-3, lo * 1e-3, hi * 1e-3) for n, t, lo, hi in pts if n > 8]
            box = [(n, t * 1e-3) for n, t, _, _ in pts if n == 8]
            colour, marker = backend_style.style(backend)
            dashed = variant == "faithful"
            label = backend if variant == "default" else f"{backend} ({variant})"
            if hull:
                # The 25-75 % range of the rounds as the error bar.
                ax.errorbar([p[0] for p in hull], [p[1] for p in hull],
                            yerr=[[p[1] - p[2] for p in hull], [p[3] - p[1] for p in hull]],
                            marker=marker, color=colour, linestyle="--" if dashed else "-",
                            label=label, capsize=2,
                            linewidth=2.5 if (backend == "custom" and not dashed) else 1.2)
            if box:
                ax.plot([p[0] for p in box], [p[1] for p in box], marker=marker, color=colour,
                        linestyle="none", markerfacecolor="none", markersize=9,
                        label=None if hull else label)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("hull vertices N (box at N = 8, open markers)")
        ax.set_ylabel("time per query (µs)")
        ax.set_title(f"Narrow phase, {pose} poses")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8, ncol=2)
        backend_style.save(fig, out, f"perf_narrowphase_{pose}")


def broadphase(rows, out):
    series = defaultdict(list)
    for r in rows:
        if r["kind"] == "broadphase" and r["ns_per_step"] is not None:
            series[r["method"]].append((r["bodies"], r["ns_per_step"] * 1e-6,
                                        (r.get("q25") or r["ns_per_step"]) * 1e-6,
                                        (r.get("q75") or r["ns_per_step"]) * 1e-6))
    if not series:
        return
    fig, ax = plt.subplots(figsize=(7, 5))
    for method, pts in sorted(series.items()):
        pts.sort()
        colour, marker = METHOD_STYLE.get(method, ("black", "o"))
        # The 25-75 % range of the rounds as the error bar.
        ax.errorbar([p[0] for p in pts], [p[1] for p in pts],
                    yerr=[[p[1] - p[2] for p in pts], [p[3] - p[1] for p in pts]],
                    marker=marker, color=colour, label=method, capsize=3)
    # A slope-1 guide through the first point of the tree.
    if "tree" in series:
        n0, t0 = sorted(series["tree"])[0][:2]
        xs = [n0, sorted(series["tree"])[-1][0]]
        ax.plot(xs, [t0 * x / n0 for x in xs], color="grey", linestyle=":", label="slope 1")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("bodies")
    ax.set_ylabel("pair finding per step (ms)")
    ax.set_title("Broad phase (same pairs from every method)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=9)
    backend_style.save(fig, out, "perf_broadphase")


def step(rows, out):
    bars = [r for r in rows if r["kind"] == "step" and r["us_per_body_step"] is not None]
    if not bars:
        return
    fig, ax = plt.subplots(figsize=(7, 4))
    # The variant on a line of its own: side by side, "custom" and "custom (faithful)" ran into
    # each other.
    labels = [f'{r["scene"]}\n{r["backend"]}' + ("" if r["variant"] == "default"
                                                 else f'\n({r["variant"]})') for r in bars]
    colours = [backend_style.colour(r["backend"], [r["backend"] for r in bars]) for r in bars]
    # A linear axis from zero: the bars' heights are then in the ratio of the times.
    heights = [r["us_per_body_step"] for r in bars]
    # The 25-75 % range of the rounds as the error bar (absent for a row without rounds).
    low = [h - (r.get("q25") if r.get("q25") is not None else h) for h, r in zip(heights, bars)]
    high = [(r.get("q75") if r.get("q75") is not None else h) - h for h, r in zip(heights, bars)]
    ax.bar(range(len(bars)), heights, color=colours, yerr=[low, high], capsize=3,
           error_kw={"elinewidth": 1})
    ax.set_xticks(range(len(bars)))
    ax.set_xticklabels(labels, fontsize=7)
    ax.set_ylim(bottom=0)
    ax.set_ylabel("µs per body per step")
    ax.set_title("Whole step, scenes/many/")
    ax.grid(True, axis="y", which="both", alpha=0.3)
    backend_style.save(fig, out, "perf_step")


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    folder = sys.argv[1]
    rows = json.load(open(os.path.join(folder, "perf.json")))["rows"]
    out = os.path.join(folder, "figures")
    os.makedirs(out, exist_ok=True)
    narrowphase(rows, out)
    broadphase(rows, out)
    step(rows, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
