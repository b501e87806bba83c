#!/usr/bin/python3
"""Figures of an rbx ensemble: per backend, the copies' final positions (the moving body whose
position spreads most, about the copies' mean, in the plane of its two widest coordinates), and
every backend's position spread against the nudge size (three sizes, log-log).

Usage: ensemble_plots.py DIR  (reads DIR/ensemble.json, writes DIR/ensemble_scatter.png and
DIR/ensemble_spread.png, each with an .svg beside it)
"""
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import backend_style  # noqa: E402

FLOOR = 1e-18  # a spread of zero is drawn at this floor on log axes


def scatter(j, out, figure="ensemble_scatter"):
    """Per backend, the copies' final positions about their mean; writes out/FIGURE.png."""
    names = [n for n in j["backends"] if j["backends"][n]["final_positions"]["positions_m"]]
    cols = min(4, max(1, len(names)))
    rows = max(1, math.ceil(len(names) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.4 * rows), squeeze=False)
    for ax in axes.flat:
        ax.set_visible(False)
    for ax, name in zip(axes.flat, names):
        ax.set_visible(True)
        fp = j["backends"][name]["final_positions"]
        pts = fp["positions_m"]
        mean = [sum(p[i] for p in pts) / len(pts) for i in range(3)]
        var = [sum((p[i] - mean[i]) ** 2 for p in pts) for i in range(3)]
        a, b = sorted(range(3), key=lambda i: -var[i])[:2]
        ax.scatter([p[a] - mean[a] for p in pts], [p[b] - mean[b] for p in pts], s=9,
                   color=backend_style.colour(name, names))
        axis = "xyz"
        ax.set_xlabel(f"{fp['body']} {axis[a]} - mean (m)")
        ax.set_ylabel(f"{axis[b]} - mean (m)")
        ax.set_title(f"{name}: {j['backends'][name]['clusters']} cluster(s)", fontsize=9)
        ax.ticklabel_format(style="sci", scilimits=(-2, 2))
    fig.suptitle(f"{j['scene']}: final positions of {j['count']} nudged copies", fontsize=10)
    backend_style.save(fig, out, figure)


def spread(j, out):
    sizes = j.get("nudge_sizes", [])
    if not sizes:
        return
    names = list(j["backends"])
    fig, ax = plt.subplots(figsize=(6, 4.4))
    x = [s["position_nudge_m"] for s in sizes]
    ax.plot(x, [max(s["input_position_m"], FLOOR) for s in sizes], color="black",
            linestyle=":", label="input")
    for k, name in enumerate(names):
        y = [max(s["position_m"].get(name, 0.0), FLOOR) for s in sizes]
        ax.plot(x, y, marker="o", label=name, color=backend_style.colour(name, names),
                linestyle="-" if k % 2 == 0 else "--")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("position nudge (m; the other nudges in proportion)")
    ax.set_ylabel("final position spread (m)")
    ax.set_title(f"{j['scene']}: spread against nudge size", fontsize=10)
    ax.legend(fontsize=7)
    backend_style.save(fig, out, "ensemble_spread")


def main(out):
    j = json.load(open(os.path.join(out, "ensemble.json")))
    scatter(j, out)
    spread(j, out)


if __name__ == "__main__":
    main(sys.argv[1])
