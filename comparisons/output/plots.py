#!/usr/bin/python3
"""Figures of an rbx report: error against run time per family, the contact-law residuals per
family (law_plots.py), the distance and time-of-impact queries' errors (query_plots.py),
per-scene velocity bars, a 3-D picture of each contact scene with every backend's contact point
and normal, and each ensemble's final positions (ensemble_plots.py).

Usage: plots.py REPORT_DIR [JOBS]  (reads results.json, error_vs_runtime.csv, laws.csv and queries.json,
writes figures/*.png and *.svg; JOBS processes share the figures, default 1)
"""
import csv
import json
import math
import multiprocessing
import os
import sys
import tomllib
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

# One (colour, marker) per backend, the same in every figure (backend_style.py).
from backend_style import order, save, style  # noqa: E402,F401


def layer(backend):
    """Drawing order: the engines under test above the libraries, so that where they agree at
    round-off (most scenes) the engine's marker is the one seen."""
    return {"custom": 6, "custom-seed": 5}.get(backend, 3)
from ensemble_plots import scatter as ensemble_scatter  # noqa: E402
from law_plots import contact_laws  # noqa: E402
from query_plots import kinds as query_kinds, query_errors  # noqa: E402


# Errors below ROUNDOFF are round-off (a few ulps of double precision on unit-sized numbers) and
# are drawn at FLOOR, inside a grey band, so that exact answers stay on a log axis.
ROUNDOFF = 1e-13
FLOOR = 1e-15


def median(values):
    """Median of a non-empty list (mean of the middle two for an even count)."""
    v = sorted(values)
    n = len(v)
    return v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])


def quartiles(values):
    """(25 %, 50 %, 75 %) of a non-empty list, linear interpolation between ranks."""
    v = sorted(values)

    def q(f):
        x = f * (len(v) - 1)
        i = int(math.floor(x))
        j = min(i + 1, len(v) - 1)
        return v[i] + (x - i) * (v[j] - v[i])
    return q(0.25), q(0.5), q(0.75)


def floored(x):
    return max(x, FLOOR) if x >= ROUNDOFF else FLOOR


def pareto(points):
    """The points no other point beats in both run time and error (lower is better)."""
    front = []
    for x, y in sorted(points):
        if not front or y < front[-1][1]:
            front.append((x, y))
    return front


def roundoff_band(ax, xlabel_side=False):
    ax.axhspan(FLOOR * 0.5, ROUNDOFF, color="#dddddd", zorder=0)
    ax.text(0.01, 0.02, f"grey: error < {ROUNDOFF:g} (round-off), drawn at {FLOOR:g}",
            transform=ax.transAxes, fontsize=7, color="#444444")


def error_vs_runtime(report, out):
    """One point per (backend, time step), and per (backend, solver budget) at the scene's step:
    the median over the family's closed-form scenes with the 25-75 % band; contacts: one point
    per backend for the normal and for the depth."""
    rows = list(csv.DictReader(open(os.path.join(report, "error_vs_runtime.csv"))))
    metrics = list(csv.DictReader(open(os.path.join(report, "metrics.csv"))))
    studies = defaultdict(list)  # (family, scene, backend) -> [(dt, runtime, error)]
    budgets = defaultdict(list)  # (family, scene, backend) -> [(budget, runtime, error)]
    qtime = defaultdict(lambda: defaultdict(list))  # family, backend -> query times (s)
    ptime = defaultdict(lambda: defaultdict(list))  # the same with the shapes prebuilt
    for r in rows:
        if r["kind"] in ("dynamics", "budget"):
            # Only closed-form references are comparable across time steps and scenes (a
            # self-consistency error is zero at the finest step by construction).
            if r["against"] != "analytic":
                continue
            point = (float(r["runtime_s"]), float(r["error"]))
            if r["kind"] == "dynamics":
                studies[(r["family"], r["scene"], r["backend"])].append((float(r["dt"]),) + point)
            else:
                budgets[(r["family"], r["scene"], r["backend"])].append((int(r["budget"]),) + point)
        elif r["kind"] == "contact-prebuilt":
            ptime[r["family"]][r["backend"]].append(float(r["runtime_s"]))
        else:
            qtime[r["family"]][r["backend"]].append(float(r["runtime_s"]))
    # Scenes differ in dt (and some set their own dt_study), so the points of a step curve are
    # the k-th step of each scene's dt study, coarse to fine; a budget curve's points are the
    # budgets themselves. Only points every scene of the family has are drawn, so the same
    # scenes stand behind every point of a curve.
    dyn = defaultdict(lambda: defaultdict(lambda: defaultdict(list)))  # family, backend, k
    bud = defaultdict(lambda: defaultdict(lambda: defaultdict(list)))  # family, backend, budget
    nscenes = defaultdict(lambda: defaultdict(int))
    nbudget = defaultdict(lambda: defaultdict(int))
    for (family, _, backend), pts in studies.items():
        nscenes[family][backend] += 1
        for k, (_, runtime, error) in enumerate(sorted(pts, reverse=True)):
            dyn[family][backend][k].append((runtime, error))
    for (family, _, backend), pts in budgets.items():
        nbudget[family][backend] += 1
        for budget, runtime, error in pts:
            bud[family][backend][budget].append((runtime, error))
    for family in sorted(set(dyn) | set(bud)):
        fig, (ax, axb) = plt.subplots(1, 2, figsize=(12.5, 6.0), sharey=True)
        allpts = []
        for panel, curves, counts in ((ax, dyn[family], nscenes[family]),
                                      (axb, bud[family], nbudget[family])):
            roundoff_band(panel)
            for backend in order(curves):
                colour, marker = style(backend)
                n = counts[backend]
                xs, ys, lo, hi, keys = [], [], [], [], []
                for k, vals in sorted(curves[backend].items()):
                    if len(vals) < n:
                        continue
                    _, tx, _ = quartiles([v[0] for v in vals])
                    q1, q2, q3 = quartiles([v[1] for v in vals])
                    xs.append(tx)
                    ys.append(floored(q2))
                    lo.append(floored(q2) - floored(q1))
                    hi.append(floored(q3) - floored(q2))
                    keys.append(k)
                if not xs:
                    continue
                panel.errorbar(xs, ys, yerr=[lo, hi], color=colour, marker=marker, ms=5, lw=1.4,
                               capsize=2, ls="-" if panel is ax else "--",
                               label=f"{backend} ({n} scenes)", zorder=layer(backend))
                if panel is ax:
                    # The coarsest step: a large open marker; its points join the Pareto front.
                    ax.scatter([xs[0]], [ys[0]], s=150, facecolors="none", edgecolors=colour,
                               lw=1.5)
                    allpts += [(x, y) for x, y in zip(xs, ys)]
                else:
                    # Each point names its budget; budgets whose points sit on one another
                    # (converged) share one label, "10-100", not labels printed over each other.
                    runs = []
                    for x, y, k in zip(xs, ys, keys):
                        if runs and abs(math.log(x / runs[-1][0])) < 0.06 and \
                                abs(math.log(y / runs[-1][1])) < 0.5:
                            runs[-1][3] = k
                        else:
                            runs.append([x, y, k, k])
                    for x, y, first, last in runs:
                        text = str(first) if first == last else f"{first}-{last}"
                        axb.annotate(text, (x, y), textcoords="offset points", xytext=(4, 3),
                                     fontsize=6, color=colour, zorder=layer(backend))
            panel.set_xscale("log")
            panel.set_yscale("log")
            panel.set_xlabel("run time of one scene run (s), median over the scenes")
            panel.grid(True, which="both", alpha=0.3)
            readable_log_ticks(panel.xaxis)
            # Below the axes: the legend hides no point.
            panel.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
        front = pareto(allpts)
        if len(front) > 1:
            ax.step([p[0] for p in front], [p[1] for p in front], where="post", color="black",
                    ls="--", lw=0.9, label="Pareto front over backends")
            ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
        ax.set_ylabel("velocity error, kinetic-energy norm:\nmedian over scenes, bar 25-75 %")
        ax.set_title("along the time step (one point per step;\nlarge open marker: the "
                     "coarsest)", fontsize=9)
        axb.set_title("along the solver budget, at the scene's step\n(each point labelled with "
                      "its budget)", fontsize=9)
        fig.suptitle(f"{family}: error against run time, closed-form scenes", fontsize=10)
        save(fig, out, f"error_vs_runtime_{family}")
    # Contacts: normal angle and depth error, each against the query time.
    con = defaultdict(lambda: defaultdict(lambda: defaultdict(list)))  # family, backend, metric
    for m in metrics:
        if m["check"] == "contact" and m["metric"] in ("normal_err_deg", "depth_err") and \
                m["against"] in ("analytic", "exact"):
            con[m["family"]][m["backend"]][m["metric"]].append(float(m["value"]))
    for family, per_backend in con.items():
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.8))
        for ax, metric, label in ((axes[0], "normal_err_deg", "normal angle error (deg)"),
                                  (axes[1], "depth_err", "depth error (m)")):
            roundoff_band(ax)
            pts = []
            for backend in order(per_backend):
                vals = per_backend[backend][metric]
                times = qtime[family].get(backend)
                if not vals or not times:
                    continue
                colour, marker = style(backend)
                t1, t2, t3 = quartiles([t * 1e6 for t in times])
                q1, q2, q3 = quartiles(vals)
                worst = max(vals)
                ax.errorbar([t2], [floored(q2)], xerr=[[t2 - t1], [t3 - t2]],
                            yerr=[[floored(q2) - floored(q1)], [floored(q3) - floored(q2)]],
                            color=colour, marker=marker, ms=7, capsize=2,
                            label=f"{backend} (worst {worst:.2g})", zorder=layer(backend))
                # The worst scene as a small hollow marker above: a known failure shows.
                ax.scatter([t2], [floored(worst)], marker=marker, s=18, facecolors="none",
                           edgecolors=colour)
                pts.append((t2, floored(q2)))
                # The same query with the library's shapes built once: a hollow marker at the
                # prebuilt median time, joined to the per-call one; the gap is the median
                # cost of building the shapes in a query.
                pre = ptime[family].get(backend)
                if pre:
                    p2 = quartiles([t * 1e6 for t in pre])[1]
                    ax.plot([p2, t2], [floored(q2), floored(q2)], color=colour, lw=0.8, ls=":")
                    ax.scatter([p2], [floored(q2)], marker=marker, s=55, facecolors="white",
                               edgecolors=colour, linewidths=1.5, zorder=3)
                    pts.append((p2, floored(q2)))
            front = pareto(pts)
            if len(front) > 1:
                ax.step([p[0] for p in front], [p[1] for p in front], where="post",
                        color="black", ls="--", lw=0.9, label="Pareto front (medians)")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("time per contact query (µs), median over scenes, bar 25-75 %\n"
                          "filled: shapes built in each query; hollow, dotted: shapes prebuilt")
            ax.set_ylabel(f"{label}: median over scenes,\nbar 25-75 %; small hollow: worst scene")
            ax.grid(True, which="both", alpha=0.3)
            readable_log_ticks(ax.xaxis)
        # One legend for both panels, below them: it hides no point.
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, [lab.split(" (worst")[0] for lab in labels], fontsize=7,
                   loc="lower center", ncol=6, bbox_to_anchor=(0.5, 0.0))
        fig.suptitle(f"{family}: contact error against query time (one point per backend; "
                     "truth: closed form, else the exact oracle)", fontsize=10)
        save(fig, out, f"error_vs_runtime_{family}-contact",
             rect=(0, 0.04 + 0.035 * ((len(labels) + 5) // 6), 1, 1))


def readable_log_ticks(axis):
    """Labels at 1, 2 and 5 times each power of ten: a log axis spanning less than a decade
    otherwise shows one number or none."""
    axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FormatStrFormatter("%g"))
    axis.set_minor_formatter(NullFormatter())


def slug(scene):
    stem = os.path.splitext(os.path.basename(scene["file"]))[0]
    return f"{scene['family']}_{stem}"


def expected_final(scene):
    """The scene's [expect.body.NAME] velocities, read from its TOML file ({} when unreadable)."""
    try:
        with open(scene["file"], "rb") as f:
            doc = tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError):
        return {}
    return doc.get("expect", {}).get("body", {})


def velocity_bars(scene, out):
    """Final linear and angular velocity of each moving body, one bar per backend; the closed
    form from the scene's [expect] as a black tick where the scene gives one."""
    backends = [b for b, r in scene["backends"].items()
                if r.get("status") == "ok" and "bodies" in r
                and any("final" in v for v in r["bodies"].values())]
    if not backends:
        return
    first = scene["backends"][backends[0]]["bodies"]
    bodies = [n for n, v in first.items() if not v.get("static") and "final" in v]
    if not bodies or len(bodies) > 6:
        return
    expect = expected_final(scene)
    labels = ["vx", "vy", "vz", "wx", "wy", "wz"]
    fig, axes = plt.subplots(1, len(bodies), figsize=(4.2 * len(bodies) + 1, 3.8), squeeze=False)
    width = 0.8 / (len(backends) + 1)
    for ax, body in zip(axes[0], bodies):
        for k, b in enumerate(backends):
            f = scene["backends"][b]["bodies"][body]["final"]
            ax.bar([i + k * width for i in range(6)], f["velocity"] + f["angular_velocity"], width,
                   label=b, color=style(b)[0])
        e = expect.get(body, {})
        truth = (e.get("velocity") or [None] * 3) + (e.get("angular_velocity") or [None] * 3)
        xs = [i + (len(backends) - 1) * width / 2 for i in range(6)]  # centre of each group
        marked = [(x, t) for x, t in zip(xs, truth) if t is not None]
        if marked:
            ax.scatter([m[0] for m in marked], [m[1] for m in marked], marker="_", s=400,
                       color="black", linewidths=2, label="closed form", zorder=3)
        ax.set_xticks(xs)
        ax.set_xticklabels(labels)
        ax.axhline(0, color="black", lw=0.6)
        ax.axvline(2.5 + (len(backends) - 1) * width / 2, color="grey", lw=0.5, ls=":")
        ax.set_title(f"body {body}: final v (m/s) and w (rad/s)", fontsize=9)
    axes[0][0].legend(fontsize=7)
    fig.suptitle(scene["scene"], fontsize=10)
    save(fig, out, f"velocity_{slug(scene)}")


def disagreeing(scene):
    """Backends the scene marks as clearly wrong (its ✗ list), in report order."""
    names = set()
    for d in scene.get("disagreements", []):
        for b in scene["backends"]:
            if d.startswith(b + " ") or d.startswith(b + ":"):
                names.add(b)
    return order(names)


def contact_picture(scene, out):
    """The bodies at t = 0, the exact contact (black) and only the backends that disagree with
    the truth, each labelled at the tip of its normal."""
    geom = scene.get("geometry") or []
    if len(geom) < 2:
        return
    fig = plt.figure(figsize=(6, 5.4))
    ax = fig.add_subplot(projection="3d")
    names = [g["name"] for g in geom[:2]]
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for g, colour in zip(geom[:2], ["#0072B2", "#E69F00"]):
        v = g["vertices"]
        tris = [[v[i] for i in t] for t in g["triangles"]]
        ax.add_collection3d(Poly3DCollection(tris, alpha=0.15, facecolor=colour, edgecolor="#555555",
                                             linewidths=0.3))
        for p in v:
            lo = [min(a, b) for a, b in zip(lo, p)]
            hi = [max(a, b) for a, b in zip(hi, p)]
    size = max(h - l for h, l in zip(hi, lo))
    arrow = 0.15 * size
    wrong = disagreeing(scene)
    shown = (["exact"] if "exact" in scene["backends"] else []) + [b for b in wrong if b != "exact"]
    # Backends with the same answer (point and normal to 1e-6) share one arrow and one label.
    groups = []
    for b in shown:
        r = scene["backends"][b]
        cs = [c for c in r.get("contacts", []) if c["bodies"][:2] == names]
        if not cs or r.get("status") != "ok":
            continue
        c = max(cs, key=lambda c: c["depth"])
        key = tuple(round(x, 6) for x in c["point"] + c["normal"] + [c["depth"]])
        for g in groups:
            if g[0] == key and b != "exact" and "exact" not in g[1]:
                g[1].append(b)
                break
        else:
            groups.append((key, [b], c))
    pts = []
    for _, members, c in groups:
        b = members[0]
        p, n = c["point"], c["normal"]
        pts.append(p)
        colour, marker = ("black", "o") if b == "exact" else style(b)
        who = ", ".join(members)
        label = f"{'exact (truth)' if b == 'exact' else who}: depth {c['depth']:.3g}"
        ax.scatter(*p, color=colour, marker=marker, s=30, label=label)
        ax.quiver(*p, *[arrow * x for x in n], color=colour, linewidth=2 if b == "exact" else 1.4)
        tip = [p[i] + 1.08 * arrow * n[i] for i in range(3)]
        ax.text(*tip, who, color=colour, fontsize=8)
    if pts:
        centre = [sum(p[i] for p in pts) / len(pts) for i in range(3)]
        small = min(max(h - l for h, l in zip(
            [max(p[i] for p in g["vertices"]) for i in range(3)],
            [min(p[i] for p in g["vertices"]) for i in range(3)])) for g in geom[:2])
        half = max(0.75 * small, 2 * arrow if small > 0.05 * size else 0.75 * small)
        for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
            setter(c - half, c + half)
    else:
        for setter, l, h in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), lo, hi):
            setter(l, h)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    who = (f"{len(wrong)} backend(s) disagree: " + ", ".join(wrong)) if wrong else \
        "every backend agrees with the truth"
    ax.set_title(f"{scene['scene']}: contact normal ({names[1]} toward {names[0]})\n{who}",
                 fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    save(fig, out, f"contact_{slug(scene)}")


def figures(report, out):
    """Every figure of the report as (function, arguments), each drawn on its own, the family
    figures (the longest) first."""
    results = json.load(open(os.path.join(report, "results.json")))
    todo = [(error_vs_runtime, (report, out)), (contact_laws, (report, out))]
    todo += [(query_errors, (report, out, kind)) for kind in query_kinds(report)]
    for scene in results["scenes"]:
        if "contact" in scene["checks"]:
            todo.append((contact_picture, (scene, out)))
        if "impulse" in scene["checks"]:
            todo.append((velocity_bars, (scene, out)))
        if "ensemble" in scene:
            todo.append((ensemble_scatter, (scene["ensemble"], out, f"ensemble_{slug(scene)}")))
    return todo


def draw(figure):
    """Draws one (function, arguments) of figures()."""
    function, args = figure
    function(*args)


def main():
    report = sys.argv[1]
    jobs = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    out = os.path.join(report, "figures")
    os.makedirs(out, exist_ok=True)
    todo = figures(report, out)
    if jobs <= 1:
        for figure in todo:
            draw(figure)
        return
    # The figures are independent: `jobs` processes share them, one at a time each, in order. A
    # figure that fails fails the whole script, as when they are drawn in turn.
    with multiprocessing.get_context("fork").Pool(jobs) as pool:
        pool.map(draw, todo, chunksize=1)


if __name__ == "__main__":
    main()
