"""Figures of the report's distance and time-of-impact sections: per query, each backend's
error against the exact oracle over explore's fixed samples, as the share of the samples it
measured with an error at most x (drawn from the quantiles every 5 % in queries.json), the
disagreement threshold as a dashed line.

Imported by plots.py; query_errors(report, out, kind) writes figures/query_KIND.png and .svg.
"""
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from backend_style import save, style  # noqa: E402

FLOOR = 1e-17  # an error at round-off or exactly 0 is drawn at this floor of the log axis
LABEL = {"distance": "distance error / true distance",
         "toi": "first-touch time error / interval"}
THRESHOLD = 1e-6  # a disagreement past it (docs/distance.md, docs/time_of_impact.md)


def kinds(report):
    """The queries queries.json holds ([] when the report ran none)."""
    path = os.path.join(report, "queries.json")
    if not os.path.exists(path):
        return []
    return [q["kind"] for q in json.load(open(path))["queries"]]


def query_errors(report, out, kind):
    doc = json.load(open(os.path.join(report, "queries.json")))
    q = next(x for x in doc["queries"] if x["kind"] == kind)
    names = [b["name"] for b in q["backends"]]
    fig, ax = plt.subplots(figsize=(10, 4.8))
    fractions = [p / 100 for p in range(0, 101, 5)]
    for k, b in enumerate(q["backends"]):
        if not b["measured"]:
            continue
        colour, marker = style(b["name"], names)
        x = [max(v, FLOOR) for v in b["quantiles_every_5"]]
        ax.step(x, fractions, where="post", color=colour, marker=marker, markersize=4,
                markevery=4, linestyle="-" if k % 2 == 0 else "--",
                label=f"{b['name']} ({b['measured']} measured, "
                      f"{100 * b['disagreements'] / b['samples']:.3g} % disagree)")
    ax.axvline(THRESHOLD, color="black", linestyle=":", linewidth=1)
    ax.text(THRESHOLD, 0.02, " disagrees past 1e-6" + (
        " (unless grazing: the pair within 1e-9 of its size of touching then)"
        if kind == "toi" else ""), fontsize=7)
    ax.set_xscale("log")
    ax.set_xlabel(LABEL[kind] + " (at or under 1e-17 drawn at it)")
    ax.set_ylabel("share of the measured samples with an error at most x")
    ax.set_ylim(0, 1.02)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6.5, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.set_title(f"rbx explore --kind {kind}, seed {doc['seed']}: {q['count']} samples "
                 "against the exact oracle", fontsize=9)
    save(fig, out, f"query_{kind}")
