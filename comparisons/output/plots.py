#!/usr/bin/python3
"""Figures of an rbx report: error against run time per family, per-scene velocity bars, and a
3-D picture of each contact scene with every backend's contact point and normal.

Usage: plots.py REPORT_DIR  (reads results.json and sweep.csv, writes figures/*.png and *.svg)
"""
import csv
import json
import math
import os
import sys
import tomllib
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

# One colour and marker per backend, stable across figures.
BACKENDS = ["custom", "exact", "fcl", "fcl-epa", "fcl-indep", "fcl-box", "libccd", "bullet",
            "bullet-sat", "mujoco", "ode"]
COLOURS = dict(zip(BACKENDS, plt.cm.tab20.colors[::2] + plt.cm.tab20.colors[1::2]))
MARKERS = dict(zip(BACKENDS, "os^vD<>pPX*"))
FLOOR = 1e-17  # errors at round-off are drawn at this floor on log axes


def median(values):
    """Median of a non-empty list (mean of the middle two for an even count)."""
    v = sorted(values)
    n = len(v)
    return v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])


def save(fig, out, name):
    fig.tight_layout()
    for ext in ("png", "svg"):
        fig.savefig(os.path.join(out, f"{name}.{ext}"), dpi=110)
    plt.close(fig)


def error_vs_runtime(report, out):
    """Dynamics: per backend, each scene's sweep and the median scene; contacts: a point per scene."""
    rows = list(csv.DictReader(open(os.path.join(report, "sweep.csv"))))
    sweeps = defaultdict(list)  # (family, scene, backend) -> [(dt, runtime, error)]
    con = defaultdict(lambda: defaultdict(list))  # family, backend
    for r in rows:
        if r["kind"] == "dynamics":
            # Only closed-form references are comparable across time steps and scenes (a
            # self-consistency error is zero at the finest step by construction).
            if r["against"] != "analytic":
                continue
            sweeps[(r["family"], r["scene"], r["backend"])].append(
                (float(r["dt"]), float(r["runtime_s"]), float(r["error"])))
        else:
            con[r["family"]][r["backend"]].append((float(r["runtime_s"]), float(r["error"])))
    # Scenes differ in dt (and some set their own sweep_dt), so the points of a curve are the
    # k-th step of each scene's sweep, coarse to fine, not one absolute dt: grouping by dt would
    # put a different set of scenes behind every point.
    dyn = defaultdict(lambda: defaultdict(lambda: defaultdict(list)))  # family, backend, k
    for (family, _, backend), pts in sweeps.items():
        for k, (_, runtime, error) in enumerate(sorted(pts, reverse=True)):
            dyn[family][backend][k].append((runtime, error))
    for family, per_backend in dyn.items():
        fig, ax = plt.subplots(figsize=(6.4, 4.6))
        for backend in sorted(per_backend, key=lambda b: BACKENDS.index(b) if b in BACKENDS else 99):
            colour = COLOURS.get(backend)
            # Thin: each scene's own sweep (its run time, its error).
            for (fam, _, b), pts in sorted(sweeps.items()):
                if fam == family and b == backend:
                    pts = sorted(pts, reverse=True)
                    ax.plot([p[1] for p in pts], [max(p[2], FLOOR) for p in pts], color=colour,
                            lw=0.7, alpha=0.3)
            # Bold: the median scene at each step of the sweeps (median run time, median error),
            # so neither one exact scene nor one failed scene decides where the curve lies.
            pts = []
            for k, vals in sorted(per_backend[backend].items()):
                pts.append((median([v[0] for v in vals]), max(median([v[1] for v in vals]), FLOOR)))
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker=MARKERS.get(backend, "o"),
                    color=colour, lw=2, label=backend)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("run time per scene (s)\npoints: each scene's time steps, coarse to fine")
        ax.set_ylabel("velocity error, kinetic-energy norm\n(bold: median scene; thin: each scene)")
        ax.set_title(f"{family}: error against run time (closed-form scenes; exact = {FLOOR:g})",
                     fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        save(fig, out, f"error_vs_runtime_{family}")
    for family, per_backend in con.items():
        fig, ax = plt.subplots(figsize=(6.4, 4.6))
        for backend in sorted(per_backend, key=lambda b: BACKENDS.index(b) if b in BACKENDS else 99):
            vals = per_backend[backend]
            xs = [v[0] * 1e6 for v in vals]
            ys = [max(v[1], FLOOR) for v in vals]
            ax.scatter(xs, ys, marker=MARKERS.get(backend, "o"), color=COLOURS.get(backend),
                       alpha=0.35, s=18)
            mean_x = math.exp(sum(math.log(max(x, 1e-3)) for x in xs) / len(xs))
            mean_y = sum(v[1] for v in vals) / len(vals)
            ax.scatter([mean_x], [max(mean_y, FLOOR)], marker=MARKERS.get(backend, "o"),
                       color=COLOURS.get(backend), s=90, edgecolors="black", label=backend)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("time per contact query (µs, median)")
        ax.set_ylabel("normal angle error (deg)")
        ax.set_title(f"{family}: contact error against query time\n(small: one scene; large: mean)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        save(fig, out, f"error_vs_runtime_{family}-contact")


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
                   label=b, color=COLOURS.get(b))
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


def contact_picture(scene, out):
    """The bodies at t = 0 with each backend's deepest contact point and its normal."""
    geom = scene.get("geometry") or []
    if len(geom) < 2:
        return
    fig = plt.figure(figsize=(6, 5.4))
    ax = fig.add_subplot(projection="3d")
    names = [g["name"] for g in geom[:2]]
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for g, colour in zip(geom[:2], ["#4c72b0", "#dd8452"]):
        v = g["vertices"]
        tris = [[v[i] for i in t] for t in g["triangles"]]
        ax.add_collection3d(Poly3DCollection(tris, alpha=0.18, facecolor=colour, edgecolor="#555555",
                                             linewidths=0.3))
        for p in v:
            lo = [min(a, b) for a, b in zip(lo, p)]
            hi = [max(a, b) for a, b in zip(hi, p)]
    # Zoom on the overlap of the two bodies' boxes when one is much larger.
    size = max(h - l for h, l in zip(hi, lo))
    arrow = 0.15 * size
    pts = []
    for b, r in scene["backends"].items():
        cs = [c for c in r.get("contacts", []) if c["bodies"][:2] == names]
        if not cs or r.get("status") != "ok":
            continue
        c = max(cs, key=lambda c: c["depth"])
        p, n = c["point"], c["normal"]
        pts.append(p)
        ax.scatter(*p, color=COLOURS.get(b), marker=MARKERS.get(b, "o"), s=30, label=b)
        ax.quiver(*p, *[arrow * x for x in n], color=COLOURS.get(b), linewidth=1.2)
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
    ax.set_title(f"{scene['scene']}\ncontact point and normal ({names[1]} toward {names[0]})", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    save(fig, out, f"contact_{slug(scene)}")


def main():
    report = sys.argv[1]
    out = os.path.join(report, "figures")
    os.makedirs(out, exist_ok=True)
    results = json.load(open(os.path.join(report, "results.json")))
    error_vs_runtime(report, out)
    for scene in results["scenes"]:
        if "contact" in scene["checks"]:
            contact_picture(scene, out)
        if "impulse" in scene["checks"]:
            velocity_bars(scene, out)


if __name__ == "__main__":
    main()
