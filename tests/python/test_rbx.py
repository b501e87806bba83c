"""The Python module rbx: the same documents as the command line, numpy where arrays belong, a
researcher's contact and response functions as backends, and clear errors.

Run by ctest (tests/CMakeLists.txt) as `python3 -m pytest tests/python`, with the module on
PYTHONPATH and RBX_EXECUTABLE naming the command-line rbx of the same build.
"""
import glob
import json
import os
import re
import subprocess
import sys
import tomllib

import numpy as np
import pytest

import rbx

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXE = os.environ.get("RBX_EXECUTABLE", os.path.join(ROOT, "build", "comparisons", "rbx"))
sys.path.insert(0, os.path.join(ROOT, "examples"))
from sat_backend import sat_contact  # noqa: E402


def without_timings(x):
    """The document with every run time and timing removed (the only things allowed to differ)."""
    if isinstance(x, dict):
        return {
            k: without_timings(v) for k, v in x.items() if "runtime" not in k and k != "timing"
        }
    if isinstance(x, list):
        return [without_timings(v) for v in x]
    return x


def cli_json(*args):
    out = subprocess.run([EXE, *args, "--json", "-"], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode in (0, 1), out.stderr
    return json.loads(out.stdout)


# -- the same answers as the command line ----------------------------------------------------

def body_steps(path):
    """What a scene costs to simulate, roughly: its bodies times its steps."""
    with open(path, "rb") as f:
        scene = tomllib.load(f)
    sim = scene.get("sim", {})
    steps = sim.get("duration", 1.0) / sim.get("dt", 1e-3)
    return len(scene.get("body", [])) * max(steps, 1.0)


def same_documents(scenes, backends):
    cli = cli_json("compare", *scenes, *(["--backends", backends] if backends else []))
    py = rbx.compare(scenes, backends=backends)
    assert len(py["scenes"]) == len(scenes)
    for a, b in zip(cli["scenes"], py["scenes"]):
        assert without_timings(a) == without_timings(b), a["scene"]


def test_compare_is_the_command_lines_document_on_every_scene():
    # Every scene's document, through the oracle (its contacts where the scene has some; a
    # dynamics scene's document says `unsupported`): the scene-level fields of every scene ...
    scenes = sorted(glob.glob(os.path.join(ROOT, "scenes", "*", "*.toml")))
    assert len(scenes) > 100
    same_documents(scenes, "exact")
    # ... and every backend the scene uses, the libraries' among them, on one scene of each
    # family, its cheapest (fewest body-steps; all of them on every scene would take minutes for
    # no other path: a library's document is built by the same code as the oracle's and the
    # engine's, and the whole library runs every backend once per test run in the library check).
    cheapest = {}
    for path in scenes:
        family = os.path.basename(os.path.dirname(path))
        cheapest[family] = min(cheapest.get(family, (float("inf"), "")), (body_steps(path), path))
    same_documents(sorted(path for _, path in cheapest.values()), None)


@pytest.mark.parametrize("scene", ["seed/face_face.toml", "analytic/headon_vertex_e05.toml",
                                   "friction/incline_slide.toml"])
def test_run_is_the_command_lines_document(scene):
    path = os.path.join(ROOT, "scenes", scene)
    backends = "custom,bullet,ode"
    assert without_timings(cli_json("run", path, "--backends", backends)) == \
        without_timings(rbx.run(path, backends=backends.split(",")))


def test_contacts_is_the_command_lines_document_and_a_dict_scene_is_a_file():
    path = os.path.join(ROOT, "scenes", "contact", "fcl_rotated_45.toml")
    assert without_timings(cli_json("contacts", path)) == without_timings(rbx.contacts(path))
    scene = {"name": "tilted", "description": "a cube turned 45 deg on a slab",
             "checks": ["contact"], "sim": {"duration": 0},
             "body": [{"name": "A", "rotation": [0, 45, 0]},
                      {"name": "B", "size": [3, 3, 3], "position": [0, 0, -1.5]}],
             "expect": {"tolerance": 1e-6, "contact": {"normal": [0, 0, 1],
                                                       "depth": 0.7071067811865476}}}
    doc = rbx.contacts(scene, backends=["exact"])
    c = doc["backends"]["exact"]["contacts"][0]
    assert np.allclose(c["normal"], [0, 0, 1]) and abs(c["depth"] - 0.5 ** 0.5) < 1e-12


def test_distance_and_toi_are_the_command_lines_documents():
    # B 0.25 above A, falling at 2 m/s: 0.25 apart now, touching at 0.25 of an interval of 0.5 s.
    scene = {"name": "fall", "description": "a cube falls onto another", "checks": ["contact"],
             "sim": {"duration": 0},
             "body": [{"name": "A"},
                      {"name": "B", "position": [0.2, 0.1, 1.25], "velocity": [0, 0, -2]}]}
    d = rbx.distance(scene, backends=["custom"])
    assert abs(d["pairs"][0]["exact"]["distance"] - 0.25) < 1e-15
    assert abs(d["pairs"][0]["backends"]["custom"]["distance"] - 0.25) < 1e-12
    t = rbx.toi(scene, interval=0.5, backends=["custom", "fcl"])
    assert t["interval"] == 0.5 and abs(t["pairs"][0]["exact"]["fraction"] - 0.25) < 1e-15
    # The same question twice, the same answers (a dict scene is a new temporary file each time).
    assert without_timings(t["pairs"]) == without_timings(
        rbx.toi(scene, interval=0.5, backends=["custom", "fcl"])["pairs"])
    path = os.path.join(ROOT, "scenes", "analytic", "corner_drop_e05.toml")
    assert without_timings(cli_json("toi", path, "--interval", "0.1")) == without_timings(
        rbx.toi(path, interval=0.1))
    for bad in (0, -1.0, float("nan"), "soon", True):
        with pytest.raises(ValueError, match="interval"):
            rbx.toi(scene, interval=bad)


def test_ensemble_is_the_command_lines_document():
    path = os.path.join(ROOT, "scenes", "seed", "edge_drop.toml")
    args = ["--count", "6", "--perturb", "orientation=1e-05", "--backends", "custom,ode"]
    assert cli_json("ensemble", path, *args) == rbx.ensemble(
        path, count=6, perturb={"orientation": 1e-5}, backends=["custom", "ode"])


def test_tosses_is_the_command_lines_document():
    data = os.path.join(ROOT, "scenes", "real", "cube_toss", "test.csv.gz")
    assert without_timings(cli_json("tosses", data, "--backends", "custom")) == \
        without_timings(rbx.tosses(data, backends=["custom"]))


def test_backends_lists_every_registry_row_with_its_kind():
    rows = {b["name"]: b for b in rbx.backends()}
    assert rows["custom-seed"]["kind"] == ["dynamics"]
    assert rows["bullet"]["kind"] == ["contact", "dynamics", "distance", "toi"]
    assert rows["ode"]["kind"] == ["contact", "dynamics"]
    assert rows["exact"]["kind"] == ["contact", "distance", "toi"]
    assert all(b["description"] for b in rows.values())


# -- numpy -----------------------------------------------------------------------------------

def test_a_trajectory_is_frames_by_bodies_by_seven():
    path = os.path.join(ROOT, "scenes", "analytic", "headon_e05.toml")
    doc = rbx.run(path, backends=["custom", "bullet"], sample_every=10)
    assert without_timings(doc) == without_timings(
        cli_json("run", path, "--backends", "custom,bullet", "--sample-every", "10"))
    for backend in ("custom", "bullet"):
        t = rbx.trajectory(doc, backend)
        assert t["states"].dtype == np.float64 and t["states"].ndim == 3
        assert t["states"].shape == (len(t["time"]), 2, 7) and len(t["time"]) > 2
        assert t["bodies"] == ["A", "B"]
        # The orientation columns are unit quaternions (the column order is right).
        assert np.allclose(np.linalg.norm(t["states"][:, :, 3:], axis=2), 1.0, atol=1e-9)
    with pytest.raises(ValueError, match="sample_every"):
        rbx.trajectory(rbx.run(path), "custom")


def test_one_contact_query_returns_numpy_arrays():
    cube = {"size": [1, 1, 1], "position": [0, 0, 0.4]}
    slab = {"vertices": np.array([[x, y, z] for x in (-2, 2) for y in (-2, 2) for z in (-1, 0)],
                                 dtype=float)}
    for backend in ("exact", "fcl"):
        cs = rbx.contact(cube, slab, backend=backend)
        assert len(cs) >= 1
        for c in cs:
            assert c["point"].shape == (3,) and c["point"].dtype == np.float64
            assert c["normal"].shape == (3,) and c["normal"].dtype == np.float64
            assert isinstance(c["depth"], float)
        deepest = max(cs, key=lambda c: c["depth"])
        # The cube's bottom at z = -0.1, the slab's top at 0: 0.1 deep, normal +z (B toward A).
        assert np.allclose(deepest["normal"], [0, 0, 1], atol=1e-6)
        assert abs(deepest["depth"] - 0.1) < 1e-6
    assert rbx.contact(cube, {"size": [1, 1, 1], "position": [5, 0, 0]}) == []


def test_a_contact_function_agrees_with_the_oracle_and_is_listed():
    rbx.register_contact_backend("py-sat", sat_contact)
    path = os.path.join(ROOT, "scenes", "contact", "fcl_rotated_45.toml")
    doc = rbx.contacts(path, backends=["py-sat", "exact"])
    ours = doc["backends"]["py-sat"]
    assert ours["status"] == "ok", ours["message"]
    assert np.allclose(ours["contacts"][0]["normal"], [0, 0, 1], atol=1e-9)
    assert abs(ours["contacts"][0]["depth"] - 0.5 ** 0.5) < 1e-9
    row = [b for b in rbx.backends() if b["name"] == "py-sat"][0]
    assert row["user"] and row["kind"] == ["contact"]


def test_registering_a_name_again_replaces_the_function_a_built_in_name_is_refused():
    a = {"size": [1, 1, 1], "position": [0, 0, 0.4]}
    b = {"size": [4, 4, 1], "position": [0, 0, -0.5]}
    first = [{"point": [0, 0, 0], "normal": [0, 0, 1], "depth": 0.1}]
    rbx.register_contact_backend("py-edited", lambda x, y: first)
    assert rbx.contact(a, b, backend="py-edited")[0]["depth"] == 0.1
    # The notebook's cell edited and run again: the new function answers, listed once.
    rbx.register_contact_backend("py-edited", lambda x, y: [dict(first[0], depth=0.2)])
    assert rbx.contact(a, b, backend="py-edited")[0]["depth"] == 0.2
    assert [r["name"] for r in rbx.backends()].count("py-edited") == 1
    with pytest.raises(ValueError, match="built-in"):
        rbx.register_contact_backend("custom", lambda x, y: first)


def test_unregister_removes_a_registered_backend_only():
    rbx.register_contact_backend("py-gone", lambda x, y: [])
    assert "py-gone" in [r["name"] for r in rbx.backends()]
    rbx.unregister("py-gone")
    assert "py-gone" not in [r["name"] for r in rbx.backends()]
    with pytest.raises(ValueError, match="no backend named 'py-gone'"):
        rbx.unregister("py-gone")
    with pytest.raises(ValueError, match="built in"):
        rbx.unregister("bullet")


def test_compare_says_whether_it_passed_and_a_failed_call_disagrees():
    # Two unit cubes overlapping by 0.1 along x: [expect.contact] holds for the custom engine; a
    # registered function that raises gives no answer, so it disagrees, naming its error.
    scene = {"checks": ["contact"], "sim": {"duration": 0},
             "body": [{"name": "A"}, {"name": "B", "position": [0.9, 0, 0]}],
             "expect": {"tolerance": 1e-9, "contact": {"normal": [-1, 0, 0], "depth": 0.1}}}

    def broken(a, b):
        raise RuntimeError("not written yet")

    rbx.register_contact_backend("py-broken", broken)
    try:
        doc = rbx.compare(scene, backends=["custom", "exact", "py-broken"])
    finally:
        rbx.unregister("py-broken")
    assert doc["passed"] and doc["scenes"][0]["passed"]
    failed = [d for d in doc["scenes"][0]["disagreements"] if d.startswith("py-broken")]
    assert len(failed) == 1 and "error" in failed[0] and "not written yet" in failed[0], failed
    wrong = dict(scene, expect={"tolerance": 1e-9, "contact": {"normal": [-1, 0, 0], "depth": 0.2}})
    doc = rbx.compare(wrong, backends=["custom", "exact"])
    assert not doc["passed"] and not doc["scenes"][0]["passed"]


def test_explore_keeps_only_the_shape_pairs_asked_for(tmp_path):
    ex = rbx.explore(count=40, backends=["fcl"], out=tmp_path, figure=False,
                     shapes=["box-box", "hull-box"])
    assert ex["shapes"] == ["box-box", "hull-box"]
    assert 0 < ex["samples_kept"] < 40 and ex["backends"]["fcl"]["samples"] == ex["samples_kept"]
    with pytest.raises(ValueError, match="--shapes"):
        rbx.explore(count=5, out=tmp_path, figure=False, shapes="box-cone")


def test_the_arguments_a_contact_function_gets():
    shapes = {}

    def probe(a, b):
        for name, body in (("a", a), ("b", b)):
            shapes[name] = {k: (v.shape, str(v.dtype)) for k, v in body.items()
                            if isinstance(v, np.ndarray)}
        if shapes["a"]["vertices"] != ((8, 3), "float64") or \
           shapes["a"]["faces"] != ((12, 3), "int64") or \
           shapes["a"]["position"] != ((3,), "float64") or \
           shapes["a"]["orientation"] != ((4,), "float64"):
            raise AssertionError(f"unexpected arguments {shapes['a']}")
        # World-frame vertices: the box of size 1 at (0, 0, 0.4) spans z 0.4 +- 0.5.
        if abs(a["vertices"][:, 2].min() + 0.1) > 1e-12:
            raise AssertionError("vertices are not in the world frame")
        return [{"point": [0, 0, 0], "normal": [0, 0, 1], "depth": 0.1}]

    rbx.register_contact_backend("py-probe", probe)
    cs = rbx.contact({"size": [1, 1, 1], "position": [0, 0, 0.4]},
                     {"size": [4, 4, 1], "position": [0, 0, -0.5]}, backend="py-probe")
    assert len(cs) == 1 and cs[0]["depth"] == 0.1


# -- a wrong function is found, and shrunk to a scene ----------------------------------------

def flipped_sat(a, b):
    """sat_contact with the normal reversed: wrong on every touching pose."""
    return [dict(c, normal=-np.asarray(c["normal"])) for c in sat_contact(a, b)]


def test_a_wrong_normal_is_flagged_and_explore_shrinks_it_to_a_scene(tmp_path):
    rbx.register_contact_backend("py-flipped", flipped_sat)
    path = os.path.join(ROOT, "scenes", "contact", "axis_z.toml")
    rbx.register_contact_backend("py-sat-2", sat_contact)
    doc = rbx.compare(path, backends=["py-flipped", "py-sat-2", "exact"])
    metrics = {(m["backend"], m["name"]): m["value"] for m in doc["scenes"][0]["metrics"]}
    assert metrics[("py-flipped", "normal_err_deg")] > 179
    assert metrics[("py-sat-2", "normal_err_deg")] < 1e-6
    ex = rbx.explore(count=60, seed=3, backends=["py-flipped", "py-sat-2"], out=tmp_path,
                     figure=False, shrink_budget=40)
    b = ex["backends"]["py-flipped"]
    # Every touching sample shows the flip (separated ones cannot); the same SAT unflipped has
    # its normals right (its disagreements, if any, are about the point it places).
    assert b["rate"] > 0.2 and all(g["signature"].endswith(" normal") for g in b["groups"])
    assert not any(g["signature"].endswith(" normal")
                   for g in ex["backends"]["py-sat-2"]["groups"])
    scenes = [g["scene"] for g in b["groups"] if g["scene"]]
    assert scenes, b["groups"]
    shrunk = os.path.join(tmp_path, "scenes", os.path.basename(scenes[0]))
    # The shrunk scene reproduces the disagreement through the harness.
    again = rbx.compare(shrunk, backends=["py-flipped", "exact"])
    flags = again["scenes"][0]["disagreements"] + \
        [m for m in again["scenes"][0]["metrics"]
         if m["backend"] == "py-flipped" and m["name"] == "normal_err_deg" and m["value"] > 90]
    assert flags


MODE = {"flip": False}


def toggled_sat(a, b):
    """sat_contact, flipped while MODE["flip"] (read in the backend's process, forked after the
    flag is set)."""
    return flipped_sat(a, b) if MODE["flip"] else sat_contact(a, b)


def test_check_names_a_registered_backend_that_got_worse_and_a_report_shows_it(tmp_path):
    rbx.register_contact_backend("py-toggled", toggled_sat, "sat_contact, flipped on demand")
    scenes = [os.path.join(ROOT, "scenes", "contact", f) for f in ("axis_z.toml",
                                                                    "fcl_rotated_45.toml")]
    baseline = tmp_path / "baseline.json"
    first = rbx.check(scenes, baseline=baseline, backends=["py-toggled"], update=True)
    assert first["passed"] and baseline.exists(), first["output"]
    assert rbx.check(scenes, baseline=baseline, backends=["py-toggled"])["passed"]
    MODE["flip"] = True
    try:
        worse = rbx.check(scenes, baseline=baseline, backends=["py-toggled"])
    finally:
        MODE["flip"] = False
    assert not worse["passed"] and worse["exit_code"] == 1
    assert "py-toggled" in worse["output"] and "normal_err_deg" in worse["output"]
    # A report written from Python ranks it and lists it with its description, like any backend
    # (the answers only: no timing repeats through Python).
    out = rbx.report(scenes, out=tmp_path / "report", backends=["py-toggled", "fcl", "exact"],
                     timing_budget=0)
    summary = open(os.path.join(out, "report.md")).read()
    assert "| **py-toggled** | sat\\_contact, flipped on demand |" in summary  # escaped
    assert any(re.match(r"\| \*\*py-toggled\*\* \| #\d+ ", line)
               for line in summary.splitlines())  # ranked in the scorecard


# -- a response function ---------------------------------------------------------------------

def seed_response(a, b, contact, e):
    """The seed's single-point impulse in numpy: the closed forms hold."""
    n, p = contact["normal"], contact["point"]
    ra, rb = p - a["position"], p - b["position"]
    v = (a["velocity"] + np.cross(a["angular_velocity"], ra)) - \
        (b["velocity"] + np.cross(b["angular_velocity"], rb))
    vn = v @ n
    if vn >= 0:
        return np.zeros(3)
    k = a["inverse_mass"] + b["inverse_mass"] + \
        np.cross(ra, n) @ a["inverse_inertia"] @ np.cross(ra, n) + \
        np.cross(rb, n) @ b["inverse_inertia"] @ np.cross(rb, n)
    return -(1 + e) * vn / k * n


def elastic_always(a, b, contact, e):
    """Ignores the restitution: every impact perfectly elastic."""
    return seed_response(a, b, contact, 1.0)


def test_a_response_that_ignores_restitution_fails_the_closed_forms():
    rbx.register_response_backend("py-seed-response", seed_response)
    rbx.register_response_backend("py-elastic", elastic_always)
    for scene in ("analytic/headon_vertex_e05.toml", "analytic/corner_drop_e05.toml"):
        path = os.path.join(ROOT, "scenes", scene)
        doc = rbx.compare(path, backends=["py-seed-response", "py-elastic", "custom-seed"])
        s = doc["scenes"][0]
        flagged = " ".join(s["expect"]["failures"] + s["disagreements"])
        assert "py-elastic" in flagged, s
        assert "py-seed-response" not in flagged, s
        # The seed's impulse written in numpy gives custom-seed's numbers, to round-off (numpy
        # sums the products in another order than Eigen).
        ours = {(m["check"], m["pair"], m["name"]): m["value"] for m in s["metrics"]
                if m["backend"] == "py-seed-response"}
        theirs = {(m["check"], m["pair"], m["name"]): m["value"] for m in s["metrics"]
                  if m["backend"] == "custom-seed"}
        assert ours.keys() == theirs.keys() and ours
        for k, v in theirs.items():
            assert abs(ours[k] - v) <= 1e-9 * max(1.0, abs(v)), (k, ours[k], v)


# -- errors ----------------------------------------------------------------------------------

def test_an_exception_or_a_wrong_return_type_is_that_backends_error():
    rbx.register_contact_backend("py-raises", lambda a, b: 1 / 0)
    rbx.register_contact_backend("py-returns-int", lambda a, b: 7)
    rbx.register_contact_backend("py-no-depth", lambda a, b: [{"point": [0, 0, 0],
                                                              "normal": [0, 0, 1]}])
    rbx.register_contact_backend("py-negative-depth", lambda a, b: [
        {"point": [0, 0, 0], "normal": [0, 0, 1], "depth": -0.1}])
    path = os.path.join(ROOT, "scenes", "contact", "axis_z.toml")
    doc = rbx.contacts(path, backends=["py-raises", "py-returns-int", "py-no-depth",
                                       "py-negative-depth", "exact"])
    bs = doc["backends"]
    assert bs["py-raises"]["status"] == "error"
    assert "ZeroDivisionError: division by zero" in bs["py-raises"]["message"]
    assert bs["py-returns-int"]["status"] == "error"
    assert "returned int" in bs["py-returns-int"]["message"]
    assert 'no "depth"' in bs["py-no-depth"]["message"]
    assert bs["py-negative-depth"]["status"] == "error"
    assert "depth -0.100000 is negative" in bs["py-negative-depth"]["message"]
    assert bs["exact"]["status"] == "ok"  # the run went on
    # The same for response functions, in a dynamics run.
    rbx.register_response_backend("py-response-raises", lambda a, b, c, e: 1 / 0)
    rbx.register_response_backend("py-response-str", lambda a, b, c, e: "up")
    run = rbx.run(os.path.join(ROOT, "scenes", "analytic", "headon_e05.toml"),
                  backends=["py-response-raises", "py-response-str", "custom-seed"])["backends"]
    assert run["py-response-raises"]["message"] == \
        "py-response-raises: ZeroDivisionError: division by zero"
    assert run["py-response-str"]["message"] == \
        "py-response-str: the impulse it returned is not a sequence of 3 numbers"
    assert run["custom-seed"]["status"] == "ok"


def test_bad_arguments_raise_with_one_line():
    with pytest.raises(TypeError, match="scene: a path or a dict"):
        rbx.compare(42)
    with pytest.raises(ValueError) as e:
        rbx.compare(os.path.join(ROOT, "no_such_scene.toml"))
    assert "no_such_scene.toml" in str(e.value) and "\n" not in str(e.value)
    with pytest.raises(ValueError, match="empty"):
        rbx.compare(os.path.join(ROOT, "scenes", "contact", "axis_z.toml"), backends=[])
    with pytest.raises(ValueError, match="unknown"):
        rbx.compare(os.path.join(ROOT, "scenes", "contact", "axis_z.toml"),
                    backends=["no-such-backend"])
    with pytest.raises(TypeError, match="fn: a function"):
        rbx.register_contact_backend("py-not-callable", 3)
    with pytest.raises(ValueError, match="built-in"):
        rbx.register_contact_backend("exact", sat_contact)
    with pytest.raises(ValueError, match="vertices must be N x 3"):
        rbx.contact({"vertices": [[0, 0, 0]]}, {"size": [1, 1, 1]})
    with pytest.raises(ValueError, match="unknown key 'mass'"):
        rbx.contact({"size": [1, 1, 1], "mass": 2}, {"size": [1, 1, 1]})
    bad_scene = {"name": "bad", "checks": ["contact"], "sim": {"duration": 0},
                 "body": [{"name": "A", "mass": -1}, {"name": "B", "position": [0, 0, -1]}]}
    with pytest.raises(ValueError, match="scene dict 'bad':.*mass"):
        rbx.compare(bad_scene)
