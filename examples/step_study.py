"""One scene's velocity error against the time step, for every dynamics backend, with matplotlib.

    ./rbx python examples/step_study.py [SCENE] [--out FILE.png]

The scene (default scenes/analytic/corner_drop_e05.toml, a cube dropped on a corner with a closed
form) is compared at four time steps (`--set sim.dt=...`); each backend's `velocity_err_ke` (the
velocity error in the kinetic-energy norm, relative) is read from the document and drawn on
log-log axes, one line per backend in its report colour.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import rbx  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "comparisons", "output"))
import backend_style  # noqa: E402

STEPS = [4e-3, 2e-3, 1e-3, 5e-4]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene", nargs="?",
                        default=os.path.join(ROOT, "scenes", "analytic", "corner_drop_e05.toml"))
    parser.add_argument("--out", default="step_study.png", help="figure file (default "
                        "step_study.png)")
    args = parser.parse_args()
    dynamics = [b["name"] for b in rbx.backends() if "dynamics" in b["kind"]]
    errors = {}  # backend -> [(dt, error)]
    for dt in STEPS:
        doc = rbx.compare(args.scene, backends=dynamics, sets={"sim.dt": dt})
        for m in doc["scenes"][0]["metrics"]:
            if m["name"] == "velocity_err_ke":
                errors.setdefault(m["backend"], []).append((dt, m["value"]))
    fig, ax = plt.subplots(figsize=(6, 4))
    print(f"{os.path.basename(args.scene)}: velocity error (kinetic-energy norm, relative)")
    print(f"{'backend':14s}" + "".join(f"{f'dt={dt:g}':>12s}" for dt in STEPS))
    for name in backend_style.order(errors):
        points = errors[name]
        colour, marker = backend_style.style(name, list(errors))
        # Zero (exact to the last bit) cannot be drawn on a log axis: shown at 1e-16.
        ax.loglog([p[0] for p in points], [max(p[1], 1e-16) for p in points], marker=marker,
                  color=colour, label=name)
        print(f"{name:14s}" + "".join(f"{p[1]:12.3g}" for p in points))
    ax.set_xlabel("time step (s)")
    ax.set_ylabel("velocity error (relative, KE norm)")
    ax.set_title(os.path.basename(args.scene))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"figure: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
