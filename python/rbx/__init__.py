"""rbx from Python: the testbed's commands as functions, and your own algorithm as a backend.

Every command runs the same code as the `rbx` executable, in this process, and returns the
document its `--json` writes (as a dict): `rbx.compare(scene)` is `rbx compare SCENE --json`.
A scene is a path to a scene file or a dict with the scene file's keys (docs/contract.md).

    import rbx
    doc = rbx.compare("scenes/contact/axis_z.toml", backends=["custom", "fcl", "exact"])
    rbx.register_contact_backend("mine", my_contact)   # fn(a, b) -> [{"point", "normal", "depth"}]
    rbx.compare("scenes/contact/axis_z.toml", backends=["mine", "exact"])

Bad input raises ValueError with the command's one-line message; a wrong argument type raises
TypeError. A registered function that raises, or returns the wrong thing, makes that backend's
result `error` with the message; the run goes on.
"""
import json
import math
import os
import tempfile

import numpy as np

import _rbx

__all__ = ["backends", "compare", "run", "trajectory", "contacts", "contact", "explore", "ensemble",
           "tosses", "check",
           "report", "register_contact_backend", "register_response_backend", "unregister",
           "scene_toml"]


# -- arguments -------------------------------------------------------------------------------

def _names(backends):
    """A --backends value from None, "a,b", "all" or a list of names."""
    if backends is None:
        return []
    if isinstance(backends, str):
        text = backends
    elif isinstance(backends, (list, tuple)) and all(isinstance(b, str) for b in backends):
        text = ",".join(backends)
    else:
        raise TypeError("backends: a list of backend names, a comma-separated string or 'all'")
    if not text.strip(", "):
        raise ValueError("backends: the list is empty; name backends (e.g. custom,fcl) or 'all'")
    return ["--backends", text]


def _sets(sets):
    """--set KEY=VALUE options from a dict {key: value} (TOML-typed) or a list of "KEY=VALUE"."""
    if sets is None:
        return []
    if isinstance(sets, dict):
        items = [f"{k}={_toml_value(v)}" for k, v in sets.items()]
    elif isinstance(sets, (list, tuple)) and all(isinstance(s, str) for s in sets):
        items = list(sets)
    else:
        raise TypeError("sets: a dict {key: value} or a list of 'KEY=VALUE' strings")
    out = []
    for s in items:
        out += ["--set", s]
    return out


def _toml_value(v):
    """A Python value as TOML text."""
    if isinstance(v, np.ndarray):
        v = v.tolist()
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        v = float(v)
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a TOML basic string
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"scene value {v!r}: not a number, string, boolean or list")


def scene_toml(scene):
    """The scene file text of a scene dict: keys as in a scene file (`sim`, `expect` tables,
    `body` a list of tables)."""
    if not isinstance(scene, dict):
        raise TypeError("scene: a dict with the scene file's keys")
    lines = []

    def table(prefix, d, array=False):
        simple = {k: v for k, v in d.items() if not isinstance(v, dict) and not (
            isinstance(v, list) and v and all(isinstance(x, dict) for x in v))}
        if prefix:
            lines.append(f"[[{prefix}]]" if array else f"[{prefix}]")
        for k, v in simple.items():
            lines.append(f"{json.dumps(str(k))} = {_toml_value(v)}")
        for k, v in d.items():
            if k in simple:
                continue
            name = f"{prefix}.{json.dumps(str(k))}" if prefix else json.dumps(str(k))
            if isinstance(v, dict):
                table(name, v)
            else:
                for item in v:
                    table(name, item, array=True)

    table("", scene)
    return "\n".join(lines) + "\n"


class _SceneFiles:
    """Scene arguments as paths: dicts are written to a temporary folder for the call."""

    def __init__(self, scenes):
        self.scenes = scenes if isinstance(scenes, (list, tuple)) else [scenes]
        self.folder = None

    def __enter__(self):
        paths = []
        for k, s in enumerate(self.scenes):
            if isinstance(s, (str, os.PathLike)):
                paths.append(os.fspath(s))
            elif isinstance(s, dict):
                if self.folder is None:
                    self.folder = tempfile.TemporaryDirectory(prefix="rbx-")
                name = str(s.get("name", f"scene{k}"))
                body = {key: v for key, v in s.items() if key != "name"}
                safe = "".join(c if c.isalnum() or c in "-_" else "_" for c in name) or "scene"
                path = os.path.join(self.folder.name, f"{safe}.toml")
                with open(path, "w") as f:
                    f.write(scene_toml(body))
                _SCENE_LABELS[path] = f"scene dict {name!r}"
                paths.append(path)
            else:
                raise TypeError("scene: a path or a dict with the scene file's keys")
        return paths

    def __exit__(self, *exc):
        for path in list(_SCENE_LABELS):
            if self.folder is not None and path.startswith(self.folder.name):
                del _SCENE_LABELS[path]
        if self.folder is not None:
            self.folder.cleanup()


# Temporary scene files written for scene dicts, and how a message names them instead.
_SCENE_LABELS = {}


def _command(args, show_progress=False):
    """Runs `rbx ARGS...` in this process: (exit code, stdout); exit code 2 raises ValueError
    with the command's message (its last line on stderr). `show_progress`: the command's stderr
    is shown as it runs (long commands), else only its message in the exception."""
    code, out, err = _rbx.command_line([str(a) for a in args], show_progress)
    if code == 2:
        lines = [ln for ln in err.splitlines() if ln.strip()]
        message = lines[-1] if lines else f"rbx {args[0]}: bad input"
        for path, label in _SCENE_LABELS.items():
            message = message.replace(path, label)
        raise ValueError(message)
    return code, out


def _with_json(args, show_progress=False):
    """The document `rbx ARGS... --json FILE` writes."""
    with tempfile.TemporaryDirectory(prefix="rbx-") as d:
        path = os.path.join(d, "out.json")
        _command(list(args) + ["--json", path], show_progress)
        with open(path) as f:
            return json.load(f)


# -- the commands ----------------------------------------------------------------------------

def backends():
    """Every backend: name, description, kind (a list of "contact", "dynamics", "distance",
    "toi": the queries it answers), whether it is
    an outside library's, applies friction, or was registered from Python (user), and its colour
    and marker in every figure ("" where it has none)."""
    rows = []
    for b in _rbx.backends():
        kind = [k for k in ("contact", "dynamics", "distance", "toi") if b[k]]
        rows.append({"name": b["name"], "description": b["description"], "kind": kind,
                     "mass": b["mass"], "library": b["library"], "friction": b["friction"],
                     "user": b["user"], "colour": b["colour"], "marker": b["marker"]})
    return rows


def compare(scene, backends=None, sets=None, force=False):
    """`rbx compare SCENE... --json`: each scene's checks, every backend side by side. `scene` is
    a path, a dict, or a list of them; `sets` overrides scene keys ({key: value})."""
    with _SceneFiles(scene) as paths:
        return _with_json(["compare", *paths, *_names(backends), *_sets(sets)] +
                          (["--force"] if force else []))


def run(scene, backends=None, sets=None, force=False, sample_every=None):
    """`rbx run SCENE --json`: collision events and final states (custom, plus `backends`);
    with `sample_every` N, each backend's trajectory every N steps (see trajectory())."""
    extra = ["--force"] if force else []
    if sample_every is not None:
        if not isinstance(sample_every, int) or sample_every <= 0:
            raise ValueError("sample_every: a positive number of steps")
        extra += ["--sample-every", sample_every]
    with _SceneFiles(scene) as paths:
        return _with_json(["run", *paths[:1], *_names(backends), *_sets(sets)] + extra)


def trajectory(doc, backend):
    """A backend's sampled trajectory from run(..., sample_every=N) as numpy arrays: "time"
    (frames,), "bodies" (names, scene order), "states" (frames x bodies x 7: position of the
    centre of mass, then the orientation quaternion w, x, y, z)."""
    result = doc["backends"][backend]
    if "trajectory" not in result:
        raise ValueError(f"{backend}: no trajectory in this document (run with sample_every)")
    t = result["trajectory"]
    states = np.asarray(t["states"], dtype=np.float64).reshape(len(t["time"]), len(t["bodies"]), 7)
    return {"time": np.asarray(t["time"], dtype=np.float64), "bodies": list(t["bodies"]),
            "states": states}


def contacts(scene, backends=None, sets=None, at=None):
    """`rbx contacts SCENE --json`: every backend's contacts at t = 0 (or at="first-contact")."""
    if at not in (None, "first-contact"):
        raise ValueError("at: None (t = 0) or 'first-contact'")
    with _SceneFiles(scene) as paths:
        return _with_json(["contacts", *paths[:1], *_names(backends), *_sets(sets)] +
                          (["--at", at] if at else []))


def distance(scene, backends=None, sets=None):
    """`rbx distance SCENE --json`: every backend's distance and closest points of every pair at
    t = 0, each against the exact oracle (docs/distance.md)."""
    with _SceneFiles(scene) as paths:
        return _with_json(["distance", *paths[:1], *_names(backends), *_sets(sets)])


def toi(scene, interval=None, backends=None, sets=None):
    """`rbx toi SCENE --json`: every backend's first touch of every pair, each body moving at its
    velocity and angular velocity over `interval` seconds (None: the scene's dt), each against
    the exact oracle (docs/time_of_impact.md)."""
    extra = []
    if interval is not None:
        if isinstance(interval, bool) or not isinstance(interval, (int, float)) or \
                not math.isfinite(interval) or interval <= 0:
            raise ValueError("interval: a positive number of seconds")
        extra = ["--interval", repr(float(interval))]
    with _SceneFiles(scene) as paths:
        return _with_json(["toi", *paths[:1], *_names(backends), *_sets(sets)] + extra)


def _body_toml(name, body):
    """A body dict of contact() as a scene file's [[body]] table."""
    if not isinstance(body, dict):
        raise TypeError(f"body {name}: a dict with 'vertices' (N x 3) or 'size', 'position', "
                        "'orientation'")
    unknown = set(body) - {"vertices", "size", "position", "orientation"}
    if unknown:
        raise ValueError(f"body {name}: unknown key {sorted(unknown)[0]!r} (vertices, size, "
                         "position, orientation)")
    spec = {"name": name}
    if "vertices" in body:
        v = np.asarray(body["vertices"], dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 3 or v.shape[0] < 4:
            raise ValueError(f"body {name}: vertices must be N x 3 with N >= 4, got shape "
                             f"{v.shape}")
        spec["shape"] = "convex"
        spec["vertices"] = v.tolist()
    elif "size" in body:
        spec["size"] = np.asarray(body["size"], dtype=np.float64).reshape(3).tolist()
    else:
        raise ValueError(f"body {name}: give 'vertices' (N x 3) or 'size' (a box)")
    if "position" in body:
        spec["position"] = np.asarray(body["position"], dtype=np.float64).reshape(3).tolist()
    if "orientation" in body:
        spec["orientation"] = np.asarray(body["orientation"],
                                         dtype=np.float64).reshape(4).tolist()
    return spec


def contact(a, b, backend="exact"):
    """One contact query: bodies A and B, each {"vertices": N x 3 (local frame) or "size": box,
    "position": [x, y, z] (of the local origin), "orientation": [w, x, y, z]}. Returns a list of
    {"point", "normal", "depth"} (numpy arrays; the normal from B toward A); empty when apart.
    Raises RuntimeError when the backend fails."""
    if not isinstance(backend, str):
        raise TypeError("backend: a backend name")
    scene = {"name": "contact", "description": "one contact query from Python",
             "checks": ["contact"], "sim": {"duration": 0},
             "body": [_body_toml("A", a), _body_toml("B", b)]}
    doc = contacts(scene, backends=[backend])
    result = doc["backends"][backend]
    if result["status"] not in ("ok", "touching"):
        raise RuntimeError(f"{backend}: {result['status']}: {result['message']}")
    return [{"point": np.asarray(c["point"], dtype=np.float64),
             "normal": np.asarray(c["normal"], dtype=np.float64),
             "depth": float(c["depth"])} for c in result["contacts"]]


def explore(count=20000, seed=1, kind="contact", backends=None, out=None, threads=0,
            shrink_budget=None, baseline=None, figure=True, shapes=None):
    """`rbx explore`: random samples against the exact oracle, disagreements grouped and each
    group shrunk to a scene under OUT/scenes/. Returns explore.json (as a dict) with "out" set to
    the folder (default reports/explore, as the command's). `shapes`: the contact kind's
    shape-class pairs kept (["box-box", "box-hull"]; classes box, hull, sliver), as --shapes."""
    if kind not in ("contact", "impact", "landing", "slide", "tunnel"):
        raise ValueError("kind: contact, impact, landing, slide or tunnel")
    args = ["explore", "--count", int(count), "--seed", int(seed), "--kind", kind,
            *_names(backends), "--threads", int(threads)]
    if out is not None:
        args += ["--out", os.fspath(out)]
    if shrink_budget is not None:
        args += ["--shrink-budget", int(shrink_budget)]
    if baseline is not None:
        args += ["--baseline", os.fspath(baseline)]
    if not figure:
        args.append("--no-figure")
    if shapes is not None:
        args += ["--shapes", ",".join([shapes] if isinstance(shapes, str) else shapes)]
    code, _ = _command(args, show_progress=True)
    folder = os.fspath(out) if out is not None else os.path.join(_source_dir(), "reports",
                                                                    "explore")
    with open(os.path.join(folder, "explore.json")) as f:
        doc = json.load(f)
    doc["out"] = folder
    doc["exit_code"] = code
    return doc


def ensemble(scene, count=50, seed=1, perturb=None, step_test=False, backends=None, sets=None):
    """`rbx ensemble SCENE --json`: `count` nudged copies through every dynamics backend (or
    `backends`); `perturb` sets nudge scales ({"position": 1e-6, "orientation": ...}, docs/
    ensemble.md); `step_test` also runs every copy at dt/10. Per backend: the spread, its
    amplification, the contact sequences, the clusters (and the step test's verdict)."""
    extra = ["--count", int(count), "--seed", int(seed)]
    for key, scale in (perturb or {}).items():
        extra += ["--perturb", f"{key}={float(scale)!r}"]
    if step_test:
        extra.append("--step-test")
    with _SceneFiles(scene) as paths:
        return _with_json(["ensemble", *paths[:1], *_names(backends), *_sets(sets)] + extra)


def tosses(data, params=None, fit=False, backends=None):
    """`rbx tosses DATA --json`: every dynamics backend against measured cube tosses."""
    args = ["tosses", os.fspath(data), *_names(backends)]
    if params is not None:
        args += ["--params", os.fspath(params)]
    if fit:
        args.append("--fit")
    return _with_json(args, show_progress=fit)  # a fit reports its progress


def check(inputs=None, baseline=None, backends=None, explore=False, no_cache=False,
          update=False):
    """`rbx check`: every accuracy metric against the baseline (default reports/baseline.json).
    Returns {"passed", "exit_code", "output"} (output: the lines the command prints, which name
    every changed metric). `update` merges this run into the baseline (`--update`)."""
    args = ["check", *[os.fspath(i) for i in (inputs or [])], *_names(backends)]
    if update:
        args.append("--update")
    if baseline is not None:
        args += ["--baseline", os.fspath(baseline)]
    if explore:
        args.append("--explore")
    if no_cache:
        args.append("--no-cache")
    code, out = _command(args, show_progress=True)
    return {"passed": code == 0, "exit_code": code, "output": out}


def report(inputs=None, out=None, backends=None, explore=False, timing_budget=None):
    """`rbx report`: the accuracy report; returns the folder it was written to.

    timing_budget: seconds each query and run is timed for, at least (`--timing-budget`;
    default 0.01); 0 calls each once, for the answers alone."""
    args = ["report", *[os.fspath(i) for i in (inputs or [])], *_names(backends)]
    if out is not None:
        args += ["--out", os.fspath(out)]
    if explore:
        args.append("--explore")
    if timing_budget is not None:
        args += ["--timing-budget", repr(float(timing_budget))]
    _command(args, show_progress=True)
    return os.fspath(out) if out is not None else os.path.join(_source_dir(), "reports", "latest")


def _source_dir():
    """The repository this module is part of (python/rbx/ inside it)."""
    return os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


# -- your own algorithm ----------------------------------------------------------------------

def _check_registration(name, fn):
    if not isinstance(name, str):
        raise TypeError("name: a string")
    if not callable(fn):
        raise TypeError("fn: a function")


def register_contact_backend(name, fn, description=None):
    """Adds `fn` as contact backend `name` for the rest of the process. fn(a, b) gets each body
    as a dict: "vertices" (N x 3, world frame), "faces" (M x 3 vertex indices, the hull's
    triangles), "position" (centre of mass, world), "orientation" ([w, x, y, z]), "name",
    "static"; it returns a list of {"point", "normal", "depth"} (normal a unit vector from B
    toward A, depth > 0 overlapping), empty when apart. The backend then runs in compare, check,
    explore and report like any other, isolated like a library (its own process, a deadline).
    Registering a name again replaces its function (edit and rerun); a built-in name is refused."""
    _check_registration(name, fn)
    _rbx.register_contact_backend(name, description or f"Python contact function {name}", fn)


def register_response_backend(name, fn, description=None):
    """Adds `fn` as dynamics backend `name`: the custom engine's seed model (its contacts, one
    point per hit) with each hit resolved by fn(a, b, contact, restitution) -> impulse (3,),
    applied +J on A and -J on B at the contact point. a and b are the contact function's body
    dicts plus "mass", "inverse_mass", "inverse_inertia" (3 x 3, world), "velocity",
    "angular_velocity"; contact is {"point", "normal" (from B toward A), "depth", "feature"}."""
    _check_registration(name, fn)
    _rbx.register_response_backend(name, description or f"Python response function {name}", fn)


def unregister(name):
    """Removes backend `name`, registered with register_contact_backend or
    register_response_backend, for the rest of the process. A built-in backend's name, or a name
    no backend has, raises ValueError."""
    if not isinstance(name, str):
        raise TypeError("name: a string")
    _rbx.unregister_backend(name)
