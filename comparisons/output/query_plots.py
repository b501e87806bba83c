"""Figures of the report's distance and time-of-impact sections, from queries.json. Per query:
left, each backend's error against the exact oracle over explore's fixed samples, as the share
of the samples it measured with an error at most x (the quantiles every 5 %), the disagreement
threshold dashed; right, its median error against its run time per query, each with its
25-75 % range as bars (the run time's spans the timed samples' sizes).

Imported by plots.py; query_errors(report, out, kind) writes figures/query_KIND.png and .svg.
"""
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from backend_style import save, style  # noqa: E402

FLOOR = 1e-17  # an error at round-off or exactly 0 is drawn at this floor of the log axes
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
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(13, 5.4), gridspec_kw={"width_ratios": [3, 2]})
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
        if b.get("timed"):
            t = [1e6 * b[key] for key in ("time_q25_s", "time_s", "time_q75_s")]
            e = [x[5], x[10], x[15]]  # the 25, 50 and 75 % quantiles
            bx.errorbar([t[1]], [e[1]], xerr=[[t[1] - t[0]], [t[2] - t[1]]],
                        yerr=[[e[1] - e[0]], [e[2] - e[1]]], color=colour, marker=marker,
                        markersize=7, capsize=3, linestyle="none")
    for axis in (ax, bx):
        axis.grid(True, which="both", alpha=0.3)
    ax.axvline(THRESHOLD, color="black", linestyle=":", linewidth=1)
    ax.text(THRESHOLD, 0.02, " disagrees past 1e-6" + (
        "\n unless grazing (the pair within\n 1e-9 of its size of touching then)"
        if kind == "toi" else ""), fontsize=7)
    ax.set_xscale("log")
    ax.set_xlabel(LABEL[kind] + " (at or under 1e-17 drawn at it)")
    ax.set_ylabel("share of the measured samples with an error at most x")
    ax.set_ylim(0, 1.02)
    ax.set_title(f"rbx explore --kind {kind}, seed {doc['seed']}: {q['count']} samples "
                 "against the exact oracle", fontsize=9)
    bx.axhline(THRESHOLD, color="black", linestyle=":", linewidth=1)
    bx.set_xscale("log")
    bx.set_yscale("log")
    bx.set_xlabel("run time per query (µs), median over the timed samples")
    bx.set_ylabel("median " + LABEL[kind])
    bx.set_title("error against run time (bars: 25-75 %)", fontsize=9)
    fig.legend(*ax.get_legend_handles_labels(), fontsize=7, loc="lower center", ncol=4,
               frameon=False)
    save(fig, out, f"query_{kind}", rect=(0, 0.14, 1, 1))
