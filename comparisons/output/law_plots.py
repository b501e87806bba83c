"""The contact-law figure of each scene family (report.md, "Contact laws"): one panel per law,
one column per backend, one marker per scene at its worst residual relative to the scene's scale
(laws.csv), the family's worst labelled.

Called by plots.py; reads REPORT_DIR/laws.csv, writes figures/contact_laws_FAMILY.png and .svg.
"""
import csv
import os
from collections import defaultdict

import matplotlib.pyplot as plt

from backend_style import order, save, style

LAWS = ["penetration", "pulling", "complementarity", "cone", "dissipation"]
# Relative residuals below ROUNDOFF are round-off of double precision on unit-sized numbers;
# they are drawn at FLOOR inside a grey band so that exact answers stay on the log axis.
ROUNDOFF = 1e-13
FLOOR = 1e-16


def read_laws(report):
    """{family: {law: {backend: [relative residual per scene]}}} from laws.csv."""
    path = os.path.join(report, "laws.csv")
    found = defaultdict(lambda: defaultdict(lambda: defaultdict(list)))
    if not os.path.exists(path):
        return found
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            found[row["family"]][row["law"]][row["backend"]].append(float(row["relative"]))
    return found


def contact_laws(report, out):
    """One figure per family: five panels, backends along x, relative residuals on a log y."""
    for family, laws in sorted(read_laws(report).items()):
        backends = order({b for law in laws.values() for b in law})
        fig, axes = plt.subplots(1, len(LAWS), figsize=(3.0 * len(LAWS), 3.6), sharey=True)
        for ax, law in zip(axes, LAWS):
            ax.axhspan(FLOOR * 0.5, ROUNDOFF, color="#dddddd", zorder=0)
            for x, b in enumerate(backends):
                values = laws[law].get(b, [])
                colour, marker = style(b, backends)
                ys = [max(v, FLOOR) if v >= ROUNDOFF else FLOOR for v in values]
                ax.plot([x] * len(ys), ys, linestyle="none", marker=marker, color=colour,
                        markerfacecolor="none", markersize=5)
            ax.set_yscale("log")
            ax.set_title(law, fontsize=9)
            ax.set_xticks(range(len(backends)))
            ax.set_xticklabels(backends, rotation=70, fontsize=7)
            ax.set_xlim(-0.6, len(backends) - 0.4)
        axes[0].set_ylabel("worst residual / scene scale")
        fig.suptitle(f"{family}: contact-law residuals, one marker per scene "
                     f"(grey: < {ROUNDOFF:g}, round-off, drawn at {FLOOR:g})", fontsize=9)
        save(fig, out, f"contact_laws_{family}")
