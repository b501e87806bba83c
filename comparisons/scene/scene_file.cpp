// Scene files (the contract's TOML format) to rbx::Scene, with validation and --set overrides.
//
// Design: toml++ parses the text into a tree; overrides are written into that tree (so the one
// validation pass covers them); then each table is checked for unknown keys and each value is
// read through a typed reader that knows the key's dotted name and line. Every failure is an
// InputError with one line: "<file>:<line>: <key>: <what is wrong>; <what would fix it>".
#include "comparisons/scene/scene_file.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "comparisons/scene/mesh_io.h"
#include "comparisons/scene/scene_reader.h"
#include "engine/format.h"

namespace rbx {

namespace {

namespace fs = std::filesystem;
using namespace scene_detail;

// ---- overrides -------------------------------------------------------------------------------

// Child table `key` of t, created when missing.
toml::table& child_table(const Reader& r, toml::table& t, const std::string& key,
                         const std::string& shown) {
  if (!t.contains(key)) t.insert(key, toml::table{});
  toml::table* c = t.get(key)->as_table();
  if (!c)
    r.fail(0, "", "--set " + shown + ": " + key + " is not a table in the scene file",
           "fix the scene file first");
  return *c;
}

// Applies one "KEY=VALUE" to the tree. "force=true" is the --force flag, not a scene key.
void apply_override(Reader& r, toml::table& root, const std::string& item, bool& force) {
  const size_t eq = item.find('=');
  auto trim = [](std::string s) {
    const size_t b = s.find_first_not_of(" \t");
    const size_t e = s.find_last_not_of(" \t");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  };
  const std::string key = trim(item.substr(0, eq));
  if (eq == std::string::npos)
    r.fail(0, "--set " + key, "missing \"=VALUE\"",
           "write --set KEY=VALUE, e.g. --set sim.dt=1e-4");
  const std::string text = trim(item.substr(eq + 1));

  // VALUE is TOML: parse "v = VALUE" so that numbers, strings, arrays keep their types.
  toml::table parsed;
  try {
    parsed = toml::parse(std::string_view("v = " + text), kOverrideSource);
  } catch (const toml::parse_error& e) {
    r.fail(0, "--set " + key,
           "cannot read \"" + text + "\" as a TOML value (" + std::string(e.description()) + ")",
           "strings need quotes (--set 'name=\"x\"'), arrays brackets (--set "
           "'body.B.velocity=[0,-1,0]')");
  }
  if (parsed.size() != 1 || !parsed.contains("v"))
    r.fail(0, "--set " + key, "\"" + text + "\" is more than one TOML value",
           "give a single value");
  toml::node& value = *parsed.get("v");

  if (key == "force") {
    if (!value.is_boolean())
      r.fail(0, "--set force", "expected true or false, got " + describe(value),
             "write force=true");
    force = value.as_boolean()->get();
    return;
  }

  // Resolve the table that receives the value and the key's canonical dotted name.
  toml::table* target = nullptr;
  std::string leaf, canonical;
  const std::vector<std::string> body_keys = keys_under("body.");
  if (starts_with(key, "body.")) {
    const std::string rest = key.substr(5);
    const size_t dot = rest.rfind('.');
    if (dot == std::string::npos)
      r.fail(0, "--set " + key, "a body key needs the body's name",
             "write --set body.NAME." + rest + "=VALUE");
    const std::string name = rest.substr(0, dot);
    leaf = rest.substr(dot + 1);
    if (std::find(body_keys.begin(), body_keys.end(), leaf) == body_keys.end())
      r.fail(0, "--set " + key, "unknown body key \"" + leaf + "\"",
             "did you mean body." + name + "." + nearest(leaf, body_keys) + "?");
    // The body with that name.
    std::vector<std::string> names;
    if (toml::array* bodies = root["body"].as_array()) {
      for (toml::node& b : *bodies) {
        toml::table* t = b.as_table();
        if (!t) continue;
        const toml::node* n = t->get("name");
        if (n && n->is_string()) {
          names.push_back(n->as_string()->get());
          if (names.back() == name && !target) target = t;
        }
      }
    }
    if (!target)
      r.fail(0, "--set " + key, "no body named \"" + name + "\" in the scene",
             names.empty() ? "add a [[body]] with that name"
                           : "did you mean body." + nearest(name, names) + "." + leaf +
                                 "? (bodies: " + join(names) + ")");
    canonical = "body." + name + "." + leaf;
  } else if (starts_with(key, "expect.body.")) {
    const std::string rest = key.substr(12);
    const size_t dot = rest.rfind('.');
    const std::vector<std::string> expect_keys = keys_under("expect.body.");
    leaf = dot == std::string::npos ? rest : rest.substr(dot + 1);
    if (dot == std::string::npos ||
        std::find(expect_keys.begin(), expect_keys.end(), leaf) == expect_keys.end())
      r.fail(0, "--set " + key, "not a key of an expected body",
             "write --set expect.body.NAME.KEY=VALUE with KEY one of " + join(expect_keys));
    const std::string name = rest.substr(0, dot);
    toml::table& expect = child_table(r, root, "expect", key);
    toml::table& bodies = child_table(r, expect, "body", key);
    target = &child_table(r, bodies, name, key);
    canonical = "expect.body." + name + "." + leaf;
  } else {
    // Any other key of the format, top-level or one section deep.
    std::vector<std::string> flat;
    for (const std::string& k : scene_keys())
      if (!starts_with(k, "body.") && !starts_with(k, "expect.body.")) flat.push_back(k);
    if (std::find(flat.begin(), flat.end(), key) == flat.end()) {
      r.fail(0, "--set " + key, "unknown key", "did you mean " + nearest(key, scene_keys()) + "?");
    }
    target = &root;
    std::string rest = key;
    for (size_t dot; (dot = rest.find('.')) != std::string::npos; rest = rest.substr(dot + 1))
      target = &child_table(r, *target, rest.substr(0, dot), key);
    leaf = rest;
    canonical = key;
  }
  target->insert_or_assign(leaf, std::move(value));
  r.mark_overridden(canonical);
}

// ---- sections --------------------------------------------------------------------------------

void read_sim(const Reader& r, const toml::table& sim, SimSettings& s,
              std::vector<double>& dt_study, bool force) {
  r.check_keys(sim, "sim.", keys_under("sim."), false);
  auto get = [&](const char* k) { return sim.get(k); };
  if (const toml::node* n = get("dt")) {
    s.dt = r.number(*n, "sim.dt", "sim.dt");
    if (!(s.dt > 0))
      r.fail(line_of(n), "sim.dt", "time step must be > 0 s, got " + num(s.dt),
             "write e.g. dt = 1e-3");
  }
  if (const toml::node* n = get("duration")) {
    s.duration = r.number(*n, "sim.duration", "sim.duration");
    if (s.duration < 0)
      r.fail(line_of(n), "sim.duration", "must be >= 0 s, got " + num(s.duration),
             "write e.g. duration = 1.0");
  }
  if (const toml::node* n = get("gravity")) s.gravity = r.vec3(*n, "sim.gravity", "sim.gravity");
  if (const toml::node* n = get("restitution")) {
    s.restitution = r.number(*n, "sim.restitution", "sim.restitution");
    if (s.restitution < 0 || s.restitution > 1)
      r.fail(line_of(n), "sim.restitution",
             "coefficient of restitution must be in [0, 1], got " + num(s.restitution),
             "use 1 for elastic, 0 for perfectly inelastic impacts");
  }
  if (const toml::node* n = get("friction")) {
    s.friction = r.number(*n, "sim.friction", "sim.friction");
    if (s.friction < 0)
      r.fail(line_of(n), "sim.friction", "Coulomb coefficient must be >= 0, got " + num(s.friction),
             "use 0 for frictionless contact");
  }
  if (const toml::node* n = get("integrator")) {
    const std::string i =
        one_of(r, *n, "sim.integrator", "sim.integrator", {"euler", "symplectic"}, "integrator");
    s.integrator = i == "euler" ? Integrator::Euler : Integrator::Symplectic;
  }
  if (const toml::node* n = get("dt_study")) {
    const toml::array& a = r.array(*n, "sim.dt_study", "sim.dt_study");
    for (size_t k = 0; k < a.size(); ++k) {
      const std::string key = "sim.dt_study[" + std::to_string(k) + "]";
      const double dt = r.number(*a.get(k), key, "sim.dt_study");
      if (!(dt > 0))
        r.fail(line_of(a.get(k)), key, "time step must be > 0 s, got " + num(dt),
               "write e.g. dt_study = [1e-2, 1e-3, 1e-4]");
      dt_study.push_back(dt);
    }
  }
  if (const toml::node* n = get("max_energy_ratio")) {
    s.max_energy_ratio = r.number(*n, "sim.max_energy_ratio", "sim.max_energy_ratio");
    if (!(s.max_energy_ratio >= 1))
      r.fail(line_of(n), "sim.max_energy_ratio",
             "energy guard must be >= 1 (a ratio to the initial energy), got " +
                 num(s.max_energy_ratio),
             "write e.g. max_energy_ratio = 1e3 (the default)");
  }

  // A run of more than 1e8 steps is refused unless forced: it is nearly always a unit slip. Even
  // forced, the count must be one a run can take (finite, at most 2^53; see kMaxStepCount).
  // Blamed key: a dt_study entry for its own step; for sim.dt, the duration when the file sets it
  // (a week at 1e-3 is a long duration), unless only the step came from --set.
  const toml::node* duration_node = sim.get("duration");
  const bool blame_duration =
      duration_node && !(r.overridden("sim.dt") && !r.overridden("sim.duration"));
  auto refuse = [&](double dt, const std::string& dt_key, const toml::node* dt_node) {
    const double steps = s.duration / dt;
    const bool countable = steps <= kMaxStepCount;  // false for inf and NaN too
    // A run takes whole steps: a duration that is no whole number of them (to 1e-9 of the
    // count, far above the round-off of the quotient) would end early or late and judge [expect]
    // at a time the file does not name; a positive duration shorter than half a step, never run.
    const double whole = std::round(steps);
    if (countable &&
        (std::abs(steps - whole) > 1e-9 * std::max(1.0, steps) || (s.duration > 0 && whole == 0))) {
      const bool duration_key = dt_key == "sim.dt" && blame_duration;
      r.fail(line_of(duration_key ? duration_node : dt_node),
             duration_key ? "sim.duration" : dt_key,
             "duration " + num(s.duration) + " s is " + num(steps) + " steps of dt = " + num(dt) +
                 " s, not a whole number",
             "choose dt so that duration / dt is a whole number (e.g. dt = " +
                 num(s.duration / std::max(1.0, std::ceil(steps))) + ")");
    }
    if (countable && (force || steps <= kMaxSteps)) return;
    const bool duration_key = dt_key == "sim.dt" && blame_duration;
    const std::string what = "duration " + num(s.duration) + " s at dt = " + num(dt) + " s is " +
                             num(steps) + " steps, ";
    r.fail(line_of(duration_key ? duration_node : dt_node), duration_key ? "sim.duration" : dt_key,
           countable ? what + "more than the limit of 1e8"
                     : what + "more than 2^53, the most a run can count, even with --force",
           countable ? "shorten duration, raise dt, or pass --force to run it anyway"
                     : "shorten duration or raise dt");
  };
  refuse(s.dt, "sim.dt", sim.get("dt"));
  if (const toml::node* n = sim.get("dt_study"))
    for (size_t k = 0; k < dt_study.size(); ++k)
      refuse(dt_study[k], "sim.dt_study[" + std::to_string(k) + "]", n->as_array()->get(k));
}

// The table of [expect.KIND] (node `n` of [expect] `t`), a question about the first two bodies:
// its keys checked, and the scene must have two.
const toml::table& pair_expectation(const Reader& r, const toml::table& t, const toml::node& n,
                                    const std::vector<BodySpec>& bodies, const std::string& kind) {
  const std::string p = "expect." + kind;
  const toml::table& c = r.table(n, p);
  r.check_keys(c, p + ".", keys_under(p + "."), false);
  if (bodies.size() < 2)
    r.fail(key_line(t, kind), p,
           "it is about the first two bodies, but the scene has " + std::to_string(bodies.size()),
           "add a second [[body]] or remove [" + p + "]");
  return c;
}

// [expect.distance]: either overlapping = true, or the distance (m, finite, >= 0).
ExpectDistance read_expect_distance(const Reader& r, const toml::table& t, const toml::node& n,
                                    const std::vector<BodySpec>& bodies) {
  const toml::table& c = pair_expectation(r, t, n, bodies, "distance");
  ExpectDistance ed;
  if (const toml::node* v = c.get("overlapping"))
    ed.overlapping = r.boolean(*v, "expect.distance.overlapping", "expect.distance.overlapping");
  const toml::node* d = c.get("distance");
  if (ed.overlapping && d)
    r.fail(line_of(d), "expect.distance.distance", "an overlapping pair has no distance",
           "remove distance, or overlapping = true");
  if (!ed.overlapping && !d)
    r.fail(key_line(t, "distance"), "expect.distance",
           "states neither a distance nor overlapping = true", "write e.g. distance = 0.25");
  if (d) {
    ed.distance = r.number(*d, "expect.distance.distance", "expect.distance.distance");
    if (!(ed.distance >= 0) || !std::isfinite(ed.distance))
      r.fail(line_of(d), "expect.distance.distance",
             "must be finite and >= 0, got " + num(ed.distance),
             "write the separation in metres, or overlapping = true");
  }
  return ed;
}

// [expect.toi]: touch = false, or touch = true with the fraction of the interval (in [0, 1]).
ExpectToi read_expect_toi(const Reader& r, const toml::table& t, const toml::node& n,
                          const std::vector<BodySpec>& bodies) {
  const toml::table& c = pair_expectation(r, t, n, bodies, "toi");
  ExpectToi et;
  const toml::node* touch = c.get("touch");
  if (!touch)
    r.fail(key_line(t, "toi"), "expect.toi", "states no touch",
           "write touch = true with fraction = ..., or touch = false");
  et.touch = r.boolean(*touch, "expect.toi.touch", "expect.toi.touch");
  const toml::node* f = c.get("fraction");
  if (et.touch != (f != nullptr))
    r.fail(line_of(f ? f : touch), f ? "expect.toi.fraction" : "expect.toi.touch",
           f ? "a pair that does not touch has no time of touch" : "a touch needs its time",
           f ? "remove fraction, or write touch = true"
             : "write fraction = the first touch's time over the interval, in [0, 1]");
  if (f) {
    et.fraction = r.number(*f, "expect.toi.fraction", "expect.toi.fraction");
    if (!(et.fraction >= 0 && et.fraction <= 1))
      r.fail(line_of(f), "expect.toi.fraction", "must be in [0, 1], got " + num(et.fraction),
             "write the first touch's time over the interval (dt)");
  }
  return et;
}

// [expect.contact] (node `n` of [expect] `t`): between the first two bodies at t = 0.
ExpectContact read_expect_contact(const Reader& r, const toml::table& t, const toml::node& n,
                                  const std::vector<BodySpec>& bodies) {
  const toml::table& c = r.table(n, "expect.contact");
  r.check_keys(c, "expect.contact.", keys_under("expect.contact."), false);
  if (bodies.size() < 2)
    r.fail(key_line(t, "contact"), "expect.contact",
           "a contact is between the first two bodies, but the scene has " +
               std::to_string(bodies.size()),
           "add a second [[body]] or remove [expect.contact]");
  ExpectContact ec;
  if (const toml::node* v = c.get("touching"))
    ec.touching = r.boolean(*v, "expect.contact.touching", "expect.contact.touching");
  if (const toml::node* v = c.get("normal")) {
    const Vec3 normal = r.vec3(*v, "expect.contact.normal", "expect.contact.normal");
    // Any non-zero direction is accepted and normalised: the expectation is a direction, and
    // hand-written ones like [1, 1, 0] are meant as such.
    if (!(normal.norm() > 0))
      r.fail(line_of(v), "expect.contact.normal", "the zero vector has no direction",
             "give the unit normal from B toward A, e.g. normal = [-1, 0, 0]");
    ec.normal = normal.normalized();
  }
  if (const toml::node* v = c.get("either_sign")) {
    ec.either_sign = r.boolean(*v, "expect.contact.either_sign", "expect.contact.either_sign");
    if (!ec.normal)
      r.fail(line_of(v), "expect.contact.either_sign", "either_sign qualifies a normal",
             "give normal = [...] beside it, or remove either_sign");
  }
  if (const toml::node* v = c.get("depth")) {
    ec.depth = r.number(*v, "expect.contact.depth", "expect.contact.depth");
    if (*ec.depth < 0)
      r.fail(line_of(v), "expect.contact.depth",
             "penetration depth must be >= 0 m, got " + num(*ec.depth),
             "depth is the overlap along the normal (use touching = false for separated bodies)");
  }
  if (const toml::node* v = c.get("point"))
    ec.point = r.vec3(*v, "expect.contact.point", "expect.contact.point");
  if (const toml::node* v = c.get("patch")) {
    const toml::array& corners = r.array(*v, "expect.contact.patch", "expect.contact.patch");
    if (corners.empty())
      r.fail(line_of(v), "expect.contact.patch", "a patch has at least one corner",
             "list its corners, e.g. patch = [[0, -0.5, 0], [0, 0.5, 0]], or remove it");
    for (size_t k = 0; k < corners.size(); ++k)
      ec.patch.push_back(r.vec3(*corners.get(k), "expect.contact.patch", "expect.contact.point"));
  }
  return ec;
}

Expect read_expect(const Reader& r, const toml::table& t, const std::vector<BodySpec>& bodies) {
  Expect e;
  r.check_keys(t, "expect.", keys_under("expect."), true);
  if (const toml::node* n = t.get("tolerance")) {
    e.tolerance = r.number(*n, "expect.tolerance", "expect.tolerance");
    if (!(e.tolerance > 0))
      r.fail(line_of(n), "expect.tolerance", "must be > 0, got " + num(e.tolerance),
             "write an absolute tolerance in SI units, e.g. tolerance = 1e-6");
  }
  if (const toml::node* n = t.get("truth")) {
    e.truth = r.string(*n, "expect.truth", "expect.truth");
    if (e.truth != "analytic" && e.truth != "exact")
      r.fail(line_of(n), "expect.truth",
             "must be \"analytic\" or \"exact\", got \"" + e.truth + "\"",
             "write truth = \"analytic\" for a closed form, \"exact\" for the oracle's answer");
  }
  // The engines under test that [expect] binds: their misses fail the scene. The custom engine
  // by default; the seed's own algorithm only where the scene says so (it lacks friction and
  // resting contact, so a new scene with either would fail on it until excused).
  if (const toml::node* n = t.get("engines")) {
    e.engines = names_from(r, *n, "expect.engines", {"custom", "custom-seed"}, "engine");
    if (e.engines.empty())
      r.fail(line_of(n), "expect.engines", "lists no engine",
             "write engines = [\"custom\"] (the default) or [\"custom\", \"custom-seed\"]");
  }
  // A closed form an engine under test is known to miss (a documented limitation): kept as the
  // truth, reported as known, and pinned by the tests so a fix is noticed. "custom-seed: why"
  // excuses the seed's algorithm, "custom: why" or plain "why" the custom engine; stored with
  // its engine named.
  if (const toml::node* n = t.get("known_failure")) {
    e.known_failure = r.string(*n, "expect.known_failure", "expect.known_failure");
    if (e.known_failure.empty())
      r.fail(line_of(n), "expect.known_failure", "is empty",
             "say why the engine misses the closed form, e.g. known_failure = \"no friction\"");
    if (!starts_with(e.known_failure, "custom: ") && !starts_with(e.known_failure, "custom-seed: "))
      e.known_failure = "custom: " + e.known_failure;
    const std::string engine = e.known_failure.substr(0, e.known_failure.find(':'));
    // It excuses an engine [expect] binds: any other would excuse nothing, silently.
    if (std::find(e.engines.begin(), e.engines.end(), engine) == e.engines.end()) {
      const auto join_quoted_list = [](const std::vector<std::string>& words) {
        std::string out;
        for (const std::string& w : words) out += (out.empty() ? "" : "\", \"") + w;
        return out;
      };
      std::vector<std::string> with = e.engines;
      with.push_back(engine);
      r.fail(line_of(n), "expect.known_failure",
             "excuses " + engine + ", which [expect] does not bind (engines = [\"" +
                 join_quoted_list(e.engines) + "\"])",
             "write engines = [\"" + join_quoted_list(with) + "\"] in [expect]");
    }
  }
  std::vector<std::string> names;
  for (const BodySpec& b : bodies) names.push_back(b.name);

  // [expect.body.NAME]: state at t = duration of a body that exists.
  if (const toml::node* n = t.get("body")) {
    const toml::table& all = r.table(*n, "expect.body");
    for (const auto& [name, node] : in_file_order(all)) {
      const std::string p = "expect.body." + name;
      if (std::find(names.begin(), names.end(), name) == names.end())
        r.fail(key_line(all, name), p, "no body named \"" + name + "\" in this scene",
               "did you mean [expect.body." + nearest(name, names) + "]? (bodies: " + join(names) +
                   ")");
      const toml::table& b = r.table(*node, p);
      r.check_keys(b, p + ".", keys_under("expect.body."), false);
      ExpectBody eb;
      eb.name = name;
      if (const toml::node* v = b.get("position"))
        eb.position = r.vec3(*v, p + ".position", "expect.body.position");
      if (const toml::node* v = b.get("velocity"))
        eb.velocity = r.vec3(*v, p + ".velocity", "expect.body.velocity");
      if (const toml::node* v = b.get("angular_velocity"))
        eb.angular_velocity = r.vec3(*v, p + ".angular_velocity", "expect.body.angular_velocity");
      e.bodies.push_back(eb);
    }
  }

  if (const toml::node* n = t.get("contact")) e.contact = read_expect_contact(r, t, *n, bodies);
  if (const toml::node* n = t.get("distance")) e.distance = read_expect_distance(r, t, *n, bodies);
  if (const toml::node* n = t.get("toi")) e.toi = read_expect_toi(r, t, *n, bodies);
  return e;
}

// [ensemble]: the copies the report runs for its Predictability section.
EnsembleSpec read_ensemble(const Reader& r, const toml::table& t, const SimSettings& sim) {
  EnsembleSpec e;
  r.check_keys(t, "ensemble.", keys_under("ensemble."), false);
  if (const toml::node* n = t.get("count")) {
    e.count = r.integer(*n, "ensemble.count", "ensemble.count");
    if (e.count < 2)
      r.fail(line_of(n), "ensemble.count",
             "must be at least 2 copies, got " + std::to_string(e.count), "write e.g. count = 50");
  }
  if (const toml::node* n = t.get("step_test"))
    e.step_test = r.boolean(*n, "ensemble.step_test", "ensemble.step_test");
  if (const toml::node* n = t.get("duration")) {
    e.duration = r.number(*n, "ensemble.duration", "ensemble.duration");
    // Whole steps of the scene's step, to 1e-9 of the count (as sim.duration).
    const double steps = e.duration / sim.dt;
    if (!(e.duration > 0 && e.duration <= sim.duration) ||
        std::abs(steps - std::round(steps)) > 1e-9 * std::max(1.0, steps))
      r.fail(line_of(n), "ensemble.duration",
             "must be > 0, at most the scene's duration " + num(sim.duration) +
                 " s and a whole number of steps of dt = " + num(sim.dt) + " s, got " +
                 num(e.duration),
             "write e.g. duration = " + num(sim.duration / 4) + ", or leave it out");
  }
  return e;
}

// True when the text holds nothing but blanks and comments.
bool blank(const std::string& text) {
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    const size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#') return false;
  }
  return true;
}

}  // namespace

Scene parse_scene(const std::string& text, const std::string& path,
                  const std::vector<std::string>& overrides) {
  Reader r(path);

  // Binary input: toml++ would complain about UTF-8 somewhere; say what it really is.
  if (const size_t nul = text.find('\0'); nul != std::string::npos)
    r.fail(static_cast<int>(std::count(text.begin(), text.begin() + nul, '\n')) + 1, "",
           "binary data (a NUL byte), not a TOML text file", "pass a .toml scene file");

  toml::table root;
  try {
    root = toml::parse(std::string_view(text), std::string_view(path));
  } catch (const toml::parse_error& e) {
    std::string what(e.description());
    if (!what.empty())
      what[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(what[0])));
    r.fail(static_cast<int>(e.source().begin.line), "malformed TOML", what,
           "fix the syntax on that line (see https://toml.io)");
  }

  // Overrides go into the tree, so that the validation below covers them.
  bool force = false;
  for (const std::string& item : overrides) apply_override(r, root, item, force);

  r.check_keys(root, "", keys_under(""), true);

  // Bodies are the one required part.
  const toml::node* body_node = root.get("body");
  if (!body_node)
    r.fail(0, "body", blank(text) ? "the scene file is empty" : "the scene has no [[body]]",
           "add at least one [[body]] with a name and a shape");
  const toml::array* body_array = body_node->as_array();
  if (!body_array || !body_array->is_array_of_tables())
    r.fail(line_of(body_node), "body",
           body_node->is_table() ? "written as a single [body] table"
                                 : "expected [[body]] tables, got " + describe(*body_node),
           "write each body as its own [[body]] table (double brackets)");
  if (body_array->empty())
    r.fail(line_of(body_node), "body", "the scene has no [[body]]",
           "add at least one [[body]] with a name and a shape");

  Scene scene;
  scene.file = path;
  scene.name = fs::path(path).stem().string();
  if (const toml::node* n = root.get("name")) {
    scene.name = r.string(*n, "name", "name");
    if (scene.name.empty())
      r.fail(line_of(n), "name", "the scene name is empty",
             "give a name or remove the key (default: file stem)");
  }
  if (const toml::node* n = root.get("description"))
    scene.description = r.string(*n, "description", "description");
  if (const toml::node* n = root.get("checks"))
    for (const std::string& c : names_from(r, *n, "checks", kChecks, "check"))
      scene.checks.push_back(*check_kind_from_string(c));
  if (const toml::node* n = root.get("backends"))
    scene.backends = names_from(r, *n, "backends", kBackends, "backend");

  if (const toml::node* n = root.get("sim"))
    read_sim(r, r.table(*n, "sim"), scene.sim, scene.dt_study, force);
  else
    read_sim(r, toml::table{}, scene.sim, scene.dt_study, force);

  // Bodies, with unique names.
  const fs::path folder = fs::path(path).parent_path();
  for (const toml::node& n : *body_array) {
    BodySpec b = read_body(r, *n.as_table(), folder, scene.input_notes);
    for (size_t k = 0; k < scene.bodies.size(); ++k)
      if (scene.bodies[k].name == b.name)
        r.fail(line_of(n.as_table()->get("name")), "body." + b.name + ".name",
               "duplicate body name \"" + b.name + "\" (the [[body]] on line " +
                   std::to_string(line_of((*body_array)[k].as_table())) + " has it too)",
               "give each body a unique name");
    scene.bodies.push_back(std::move(b));
  }

  if (const toml::node* n = root.get("expect"))
    scene.expect = read_expect(r, r.table(*n, "expect"), scene.bodies);
  if (const toml::node* n = root.get("ensemble"))
    scene.ensemble = read_ensemble(r, r.table(*n, "ensemble"), scene.sim);
  // [expect] is the closed form of the physics the file describes: an override of that physics
  // (a body, gravity, restitution, friction, the duration it is judged at) sets it aside, to be
  // reported as not checked with the key that changed it. A step size, the integrator, the
  // checks, the backends or the expectation itself leave it standing.
  static const std::vector<std::string> kKeepExpect = {"sim.dt",
                                                       "sim.dt_study",
                                                       "sim.integrator",
                                                       "sim.max_energy_ratio",
                                                       "name",
                                                       "description",
                                                       "checks",
                                                       "backends",
                                                       "force",
                                                       "ensemble.count",
                                                       "ensemble.step_test",
                                                       "ensemble.duration"};
  if (scene.expect)
    for (const std::string& key : r.overridden_keys())
      if (!starts_with(key, "expect.") &&
          std::find(kKeepExpect.begin(), kKeepExpect.end(), key) == kKeepExpect.end())
        scene.expect_set_aside_by.push_back("--set " + key);
  return scene;
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw InputError(path + ": is a folder, not a scene file; pass a .toml file");
  if (fs::exists(path, ec) && !fs::is_regular_file(path, ec))  // /dev/zero, a FIFO: endless read
    throw InputError(path + ": is not a regular file (a device or a pipe); pass a .toml file");
  std::ifstream file(path, std::ios::binary);
  if (!file)
    throw InputError(path + ": cannot open the scene file (" + std::strerror(errno) +
                     "); check the path");
  std::ostringstream text;
  text << file.rdbuf();
  return parse_scene(text.str(), path, overrides);
}

}  // namespace rbx
