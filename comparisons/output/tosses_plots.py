#!/usr/bin/python3
"""Figures of the report's "Real impacts" section (measured cube tosses).

Usage: tosses_plots.py REPORT_DIR
Reads tosses_per_toss.csv, tosses_error_time.csv and tosses_traj.csv (written by rbx report),
writes figures/tosses_errors.{png,svg} and figures/tosses_trajectories.{png,svg}.
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

import backend_style  # noqa: E402


def rows(path):
    """The rows of a CSV file as dicts."""
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def colour_of(names):
    """Each backend's colour, the same in every figure (backend_style.py)."""
    return {n: backend_style.colour(n, names) for n in names}


def error_figure(report, out):
    """Per-toss position error distribution (box plots) and the median error over time."""
    per = rows(os.path.join(report, "tosses_per_toss.csv"))
    by = defaultdict(list)  # (params, backend) -> errors
    for r in per:
        by[(r["params"], r["backend"])].append(float(r["position_error"]))
    names = sorted({b for _, b in by}, key=lambda b: sorted(by.get(("stored", b), [1e9]))[
        len(by.get(("stored", b), [1e9])) // 2])
    colours = colour_of(names)
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.5))
    # Per backend its two boxes side by side (fitted dark, published light), one label between
    # them, rotated so that long names never overlap.
    data, positions, cols, alphas, ticks = [], [], [], [], []
    for i, b in enumerate(names):
        for k, p in enumerate(("stored", "published")):
            if (p, b) in by:
                data.append(by[(p, b)])
                positions.append(3 * i + 1 + k)
                cols.append(colours[b])
                alphas.append(0.85 if p == "stored" else 0.3)
        ticks.append(3 * i + 1.5)
    parts = ax.boxplot(data, positions=positions, whis=(10, 90), showfliers=True,
                       patch_artist=True, widths=0.8)
    for patch, c, a in zip(parts["boxes"], cols, alphas):
        patch.set_facecolor(c)
        patch.set_alpha(a)
    ax.set_xticks(ticks)
    ax.set_xticklabels(names, fontsize=8, rotation=35, ha="right")
    ax.legend(handles=[Patch(facecolor="grey", alpha=0.85, label="fitted parameters"),
                       Patch(facecolor="grey", alpha=0.3, label="published parameters")],
              fontsize=8, loc="upper left")
    ax.set_yscale("log")
    ax.set_ylabel("mean position error per toss (cube widths)")
    ax.set_title("position error per toss (box: quartiles, whiskers: 10-90 %)")
    ax.grid(True, axis="y", alpha=0.3)

    series = defaultdict(lambda: ([], []))
    for r in rows(os.path.join(report, "tosses_error_time.csv")):
        t, e = series[r["backend"]]
        t.append(float(r["t"]))
        e.append(float(r["median_position_error"]))
    for b in names:
        if b in series:
            bx.plot(*series[b], color=colours[b], label=b)
    bx.set_xlabel("time after release (s)")
    bx.set_ylabel("median position error over tosses (cube widths)")
    bx.set_title("error over time, fitted parameters")
    bx.grid(True, alpha=0.3)
    bx.legend(fontsize=8)
    backend_style.save(fig, out, "tosses_errors")


def trajectory_figure(report, out):
    """Measured and simulated height and rotation angle of the three chosen tosses."""
    traj = rows(os.path.join(report, "tosses_traj.csv"))
    if not traj:
        return
    picks = []
    for r in traj:
        if (r["pick"], r["toss"]) not in picks:
            picks.append((r["pick"], r["toss"]))
    sources = sorted({r["source"] for r in traj if r["source"] != "measured"})
    colours = colour_of(sources)
    fig, axes = plt.subplots(len(picks), 2, figsize=(12, 3.2 * len(picks)), squeeze=False)
    for k, (pick, toss) in enumerate(picks):
        for src in ["measured"] + sources:
            pts = [r for r in traj if r["pick"] == pick and r["toss"] == toss and r["source"] == src]
            if not pts:
                continue
            t = [float(r["t"]) for r in pts]
            style = dict(color="black", lw=2.2, label="measured") if src == "measured" else dict(
                color=colours[src], lw=1.1, label=src)
            axes[k][0].plot(t, [float(r["z"]) * 100 for r in pts], **style)
            axes[k][1].plot(t, [float(r["angle_deg"]) for r in pts], **style)
        axes[k][0].set_ylabel("height of centre (cm)")
        axes[k][1].set_ylabel("rotation from release (deg)")
        axes[k][0].set_title(f"{pick} toss ({toss}): height")
        axes[k][1].set_title(f"{pick} toss ({toss}): angle")
        for a in axes[k]:
            a.grid(True, alpha=0.3)
            a.set_xlabel("time after release (s)")
    axes[0][0].legend(fontsize=8)
    backend_style.save(fig, out, "tosses_trajectories")


def main():
    report = sys.argv[1]
    out = os.path.join(report, "figures")
    os.makedirs(out, exist_ok=True)
    error_figure(report, out)
    trajectory_figure(report, out)


if __name__ == "__main__":
    main()
