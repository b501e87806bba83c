#!/usr/bin/python3
"""Figure of an rbx explore run: per backend, the distribution of each error against the exact
oracle (normal angle, depth and point error relative to the smaller body), drawn from the
quantiles stored in explore.json (every 5 %).

Usage: explore_plots.py DIR  (reads DIR/explore.json, writes DIR/explore_errors.png and .svg)
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import backend_style  # noqa: E402

FLOOR = 1e-17  # errors at round-off are drawn at this floor on log axes
METRICS = [("normal_err_deg", "normal error (deg)"),
           ("depth_err_rel", "depth error / smaller body size"),
           ("point_err_rel", "point error / smaller body size"),
           ("coverage_err_rel", "patch coverage error / smaller body size")]


def main(out):
    j = json.load(open(os.path.join(out, "explore.json")))
    names = list(j["backends"])
    # The metrics the document has (one written before patch coverage was measured has none).
    metrics = [(key, label) for key, label in METRICS
               if any(key in j["backends"][n]["errors"] for n in names)]
    if not metrics:
        sys.exit(f"explore_plots.py: no contact-kind errors in {out}/explore.json "
                 f"(kind {j.get('kind', '?')}): no figure")
    fig, axes = plt.subplots(1, len(metrics), figsize=(5 * len(metrics), 4.2), sharey=True)
    for ax, (key, label) in zip(axes, metrics):
        for k, name in enumerate(names):
            e = j["backends"][name]["errors"].get(key)
            if not e or not e["n"]:
                continue
            q = [max(v, FLOOR) for v in e["quantiles_every_5"]]
            frac = [p / 100 for p in range(0, 101, 5)]
            ax.step(q, frac, where="post", label=f"{name} (n={e['n']})",
                    color=backend_style.colour(name, names),
                    linestyle="-" if k % 2 == 0 else "--")
        ax.set_xscale("log")
        ax.set_xlabel(label)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("fraction of samples with both touching")
    axes[-1].legend(fontsize=7, loc="lower right")
    fig.suptitle(f"rbx explore: {j['count']} samples, seed {j['seed']}, errors against the exact oracle")
    backend_style.save(fig, out, "explore_errors")


if __name__ == "__main__":
    main(sys.argv[1])
