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
#include "engine/format.h"

namespace rbx {

namespace {

namespace fs = std::filesystem;

// Every key of the format with an example value for messages ("write e.g. mass = 1.0").
// Generic names: a body's keys are "body.KEY", an expected body's "expect.body.KEY".
struct KeyInfo {
  const char* key;
  const char* example;
};

const KeyInfo kKeys[] = {
    {"name", "\"cube face-face\""},
    {"description", "\"...\""},
    {"checks", "[\"impulse\"]"},
    {"backends", "[\"custom\", \"bullet\"]"},
    {"sim.dt", "1e-3"},
    {"sim.duration", "1.0"},
    {"sim.gravity", "[0, 0, -9.81]"},
    {"sim.restitution", "1.0"},
    {"sim.friction", "0.0"},
    {"sim.integrator", "\"symplectic\""},
    {"sim.sweep_dt", "[1e-2, 1e-3, 1e-4]"},
    {"sim.max_energy_ratio", "1e3"},
    {"body.name", "\"A\""},
    {"body.shape", "\"box\""},
    {"body.size", "[1, 1, 1]"},
    {"body.radius", "0.5"},
    {"body.subdivisions", "2"},
    {"body.height", "1.0"},
    {"body.sides", "6"},
    {"body.vertices", "[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]"},
    {"body.file", "\"meshes/part.obj\""},
    {"body.hull", "true"},
    {"body.mass", "1.0"},
    {"body.static", "false"},
    {"body.mass_model", "\"solid\""},
    {"body.position", "[0, 0, 0]"},
    {"body.rotation", "[0, 0, 0]"},
    {"body.orientation", "[1, 0, 0, 0]"},
    {"body.velocity", "[0, 0, 0]"},
    {"body.angular_velocity", "[0, 0, 0]"},
    {"expect.tolerance", "1e-6"},
    {"expect.known_failure",
     "\"custom: no resting contact (seed correction 12 (what the seed admits it lacks))\""},
    {"expect.body.position", "[0, 0, 0]"},
    {"expect.body.velocity", "[0, 0, 0]"},
    {"expect.body.angular_velocity", "[0, 0, 0]"},
    {"expect.contact.touching", "true"},
    {"expect.contact.normal", "[-1, 0, 0]"},
    {"expect.contact.either_sign", "true"},
    {"expect.contact.depth", "0.1"},
    {"expect.contact.point", "[0, 0, 0]"},
};

const std::vector<std::string> kChecks = {"contact", "impulse", "trajectory", "stability", "mass"};
const std::vector<std::string> kBackends = {
    "custom",    "custom-seed", "exact",      "fcl",     "fcl-hull",    "fcl-epa",
    "fcl-indep", "libccd-mpr",  "libccd-epa", "bullet",  "bullet-hull", "bullet-sat",
    "mujoco",    "mujoco-hull", "ode",        "ode-hull"};
const std::vector<std::string> kShapes = {"box", "icosphere", "prism", "convex", "mesh"};

// Shape-specific body keys and the shape that owns them.
const std::vector<std::pair<std::string, std::string>> kShapeKeys = {
    {"size", "box"},        {"radius", "icosphere"}, {"subdivisions", "icosphere"},
    {"radius", "prism"},    {"height", "prism"},     {"sides", "prism"},
    {"vertices", "convex"}, {"file", "mesh"},        {"hull", "mesh"},
};

// More steps than this is almost surely a typo (1e8 steps of a two-body scene is minutes).
constexpr double kMaxSteps = 1e8;

// Quaternions must be unit within this: a value a float32 library wrote (its components rounded
// to ~6e-8, norm off by up to ~1e-7) or one printed with >= 7 significant digits passes and is
// normalised (the results say so), while a hand-typed [0.7071, 0.7071, 0, 0] (norm 1 - 1e-5) or
// a non-rotation like [1, 1, 0, 0] fails instead of being silently renormalised into a rotation
// the author did not write down.
constexpr double kUnitQuaternionTolerance = 1e-6;

// Keys of the sub-tables of one level, from the table above: prefix "sim." -> {"dt", ...}.
std::vector<std::string> keys_under(const std::string& prefix) {
  std::vector<std::string> out;
  for (const KeyInfo& k : kKeys) {
    const std::string key = k.key;
    if (key.compare(0, prefix.size(), prefix) != 0) continue;
    std::string rest = key.substr(prefix.size());
    rest = rest.substr(0, rest.find('.'));
    if (std::find(out.begin(), out.end(), rest) == out.end()) out.push_back(rest);
  }
  return out;
}

const char* example_of(const std::string& generic) {
  for (const KeyInfo& k : kKeys)
    if (generic == k.key) return k.example;
  return "...";
}

bool starts_with(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

// Levenshtein distance, for "did you mean".
size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// The candidate nearest to `word`; ties go to the longer common prefix ("simulation" is as far
// from "description" as from "sim"), then to the first listed.
std::string nearest(const std::string& word, const std::vector<std::string>& candidates) {
  auto common_prefix = [&](const std::string& c) {
    size_t k = 0;
    while (k < word.size() && k < c.size() && word[k] == c[k]) ++k;
    return k;
  };
  std::string best;
  size_t best_distance = SIZE_MAX, best_prefix = 0;
  for (const std::string& c : candidates) {
    const size_t d = edit_distance(word, c), prefix = common_prefix(c);
    if (d < best_distance || (d == best_distance && prefix > best_prefix)) {
      best_distance = d;
      best_prefix = prefix;
      best = c;
    }
  }
  return best;
}

// "a\" or \"b": for "shape = \"icosphere\" or \"prism\"".
std::string join_quoted(const std::vector<std::string>& words) {
  std::string out;
  for (size_t k = 0; k < words.size(); ++k) out += (k ? "\" or \"" : "") + words[k];
  return out;
}

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

// Shortest decimal that reads back as the same double ("0.1", "1e-05", "nan", "-inf"); below a
// million, all integer digits ("604800", not "6.048e+05").
std::string num(double v) {
  NumberFormat f;
  f.digits = 0;
  f.signed_zero = true;
  f.integer_digits = true;
  return format_number(v, f);
}

// Ten significant digits: enough to show how far from 1 a norm is.
std::string fixed10(double v) {
  NumberFormat f;
  f.digits = 10;
  f.signed_zero = true;
  return format_number(v, f);
}

std::string vec_text(const Vec3& v) {
  return "[" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + "]";
}

// What a TOML value is, for "expected X, got Y" messages.
std::string describe(const toml::node& n) {
  if (const auto* s = n.as_string()) {
    std::string text = s->get();
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    return "the string \"" + text + "\"";
  }
  if (const auto* i = n.as_integer()) return "the integer " + std::to_string(i->get());
  if (const auto* f = n.as_floating_point()) {
    std::string text = num(f->get());
    if (std::isfinite(f->get()) && text.find_first_of(".e") == std::string::npos) text += ".0";
    return "the number " + text;
  }
  if (const auto* b = n.as_boolean()) return b->get() ? "true" : "false";
  if (const auto* a = n.as_array()) return "an array of " + std::to_string(a->size());
  if (n.is_table()) return "a table";
  return "a date/time";
}

// Replaces line breaks so that a message stays one line.
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

// Entries of a table in file order (toml++ keeps them sorted by key), so that the first
// offending line of the file is the one reported.
std::vector<std::pair<std::string, const toml::node*>> in_file_order(const toml::table& t) {
  std::vector<std::tuple<uint32_t, std::string, const toml::node*>> entries;
  for (auto&& [key, node] : t) {
    const uint32_t line = key.source().begin.line ? key.source().begin.line : UINT32_MAX;
    entries.emplace_back(line, std::string(key.str()), &node);
  }
  std::stable_sort(entries.begin(), entries.end(),
                   [](const auto& a, const auto& b) { return std::get<0>(a) < std::get<0>(b); });
  std::vector<std::pair<std::string, const toml::node*>> out;
  for (const auto& [line, key, node] : entries) out.emplace_back(key, node);
  return out;
}

// Line of a key within its table (0 if unknown).
int key_line(const toml::table& t, const std::string& key) {
  for (auto&& [k, node] : t)
    if (k.str() == key) return static_cast<int>(k.source().begin.line);
  return 0;
}

// Source name of values parsed from --set: they have no line in the scene file.
constexpr std::string_view kOverrideSource = "--set";

// Line of a value in the scene file (0 if none, as for values from --set).
int line_of(const toml::node* n) {
  if (!n) return 0;
  const toml::source_region& src = n->source();
  if (src.path && *src.path == kOverrideSource) return 0;
  return static_cast<int>(src.begin.line);
}

// Where messages point: the file as given, and which keys came from --set (no file line).
class Reader {
 public:
  explicit Reader(std::string path) : path_(std::move(path)) {}

  const std::string& path() const { return path_; }
  void mark_overridden(const std::string& key) { overridden_.insert(key); }
  /// True when `key` (or a table holding it) was set by --set.
  bool overridden(const std::string& key) const { return is_overridden(key); }
  /// Every key --set changed, by its canonical dotted name.
  const std::set<std::string>& overridden_keys() const { return overridden_; }

  /// Throws the one-line InputError. `line` 0 means no line; an overridden key is shown as
  /// "--set KEY" without a line, since its value is not in the file.
  [[noreturn]] void fail(int line, const std::string& key, const std::string& what,
                         const std::string& fix) const {
    std::string where = path_;
    std::string shown = key;
    if (is_overridden(key)) {
      shown = "--set " + key;
    } else if (line > 0) {
      where += ":" + std::to_string(line);
    }
    std::string message = where + ": ";
    if (!shown.empty()) message += shown + ": ";
    message += what;
    if (!fix.empty()) message += "; " + fix;
    throw InputError(one_line(message));
  }

  // Typed readers: each checks the TOML type, finiteness and shape, and names the key.

  double number(const toml::node& n, const std::string& key, const std::string& generic) const {
    double v = 0;
    if (const auto* i = n.as_integer()) {
      v = static_cast<double>(i->get());
    } else if (const auto* f = n.as_floating_point()) {
      v = f->get();
    } else {
      fail(line_of(&n), key, "expected a number, got " + describe(n), write_eg(generic));
    }
    if (!std::isfinite(v))
      fail(line_of(&n), key, "must be a finite number, got " + num(v),
           "write a finite value (TOML's nan and inf are not allowed here)");
    return v;
  }

  long integer(const toml::node& n, const std::string& key, const std::string& generic) const {
    const auto* i = n.as_integer();
    if (!i) fail(line_of(&n), key, "expected an integer, got " + describe(n), write_eg(generic));
    return static_cast<long>(i->get());
  }

  bool boolean(const toml::node& n, const std::string& key, const std::string& generic) const {
    const auto* b = n.as_boolean();
    if (!b) fail(line_of(&n), key, "expected true or false, got " + describe(n), write_eg(generic));
    return b->get();
  }

  std::string string(const toml::node& n, const std::string& key,
                     const std::string& generic) const {
    const auto* s = n.as_string();
    if (!s) fail(line_of(&n), key, "expected a string, got " + describe(n), write_eg(generic));
    return s->get();
  }

  const toml::array& array(const toml::node& n, const std::string& key,
                           const std::string& generic) const {
    const auto* a = n.as_array();
    if (!a) fail(line_of(&n), key, "expected an array, got " + describe(n), write_eg(generic));
    return *a;
  }

  const toml::table& table(const toml::node& n, const std::string& key) const {
    const auto* t = n.as_table();
    if (!t)
      fail(line_of(&n), key, "expected a table, got " + describe(n),
           "write it as a section [" + key + "]");
    return *t;
  }

  /// A fixed-length list of numbers, named by component ("x", "y", "z" or "w", "x", ...).
  std::vector<double> numbers(const toml::node& n, const std::string& key,
                              const std::string& generic,
                              const std::vector<std::string>& components) const {
    const toml::array& a = array(n, key, generic);
    if (a.size() != components.size())
      fail(line_of(&n), key,
           "expected " + std::to_string(components.size()) + " numbers [" + join(components) +
               "], got " + std::to_string(a.size()),
           write_eg(generic));
    std::vector<double> out;
    for (size_t k = 0; k < a.size(); ++k) {
      const toml::node& e = *a.get(k);
      const std::string component = "component " + components[k];
      if (!e.is_number())
        fail(line_of(&e), key, component + " is " + describe(e) + ", not a number",
             write_eg(generic));
      out.push_back(e.is_integer() ? static_cast<double>(e.as_integer()->get())
                                   : e.as_floating_point()->get());
      if (!std::isfinite(out.back()))
        fail(line_of(&e), key, component + " is " + num(out.back()) + ", not a finite number",
             "write finite values (TOML's nan and inf are not allowed here)");
    }
    return out;
  }

  Vec3 vec3(const toml::node& n, const std::string& key, const std::string& generic) const {
    const std::vector<double> v = numbers(n, key, generic, {"x", "y", "z"});
    return Vec3(v[0], v[1], v[2]);
  }

  /// Unknown keys of a table, first in file order, with the nearest valid key suggested.
  void check_keys(const toml::table& t, const std::string& prefix,
                  const std::vector<std::string>& allowed, bool sections) const {
    for (const auto& [key, node] : in_file_order(t)) {
      if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
      const std::string best = nearest(key, allowed);
      const bool section = sections && node->is_table();
      fail(key_line(t, key), prefix + key,
           section ? "unknown section [" + prefix + key + "]" : "unknown key",
           "did you mean " + (section ? "[" + prefix + best + "]" : prefix + best) +
               "? (valid here: " + join(allowed) + ")");
    }
  }

 private:
  bool is_overridden(const std::string& key) const {
    for (const std::string& o : overridden_)
      if (o == key || starts_with(key, o + ".") || starts_with(key, o + "[") ||
          starts_with(o, key + "."))
        return true;
    return false;
  }

  static std::string write_eg(const std::string& generic) {
    const std::string leaf = generic.substr(generic.rfind('.') + 1);
    return "write e.g. " + leaf + " = " + example_of(generic);
  }

  std::string path_;
  std::set<std::string> overridden_;
};

// A name from a fixed list, with "did you mean" for anything else.
std::string one_of(const Reader& r, const toml::node& n, const std::string& key,
                   const std::string& generic, const std::vector<std::string>& allowed,
                   const std::string& what) {
  const std::string s = r.string(n, key, generic);
  if (std::find(allowed.begin(), allowed.end(), s) == allowed.end())
    r.fail(line_of(&n), key, "unknown " + what + " \"" + s + "\"",
           "did you mean \"" + nearest(s, allowed) + "\"? (" + what + "s: " + join(allowed) + ")");
  return s;
}

// A list of names from a fixed list (checks, backends), no repeats.
std::vector<std::string> names_from(const Reader& r, const toml::node& n, const std::string& key,
                                    const std::vector<std::string>& allowed,
                                    const std::string& what) {
  std::vector<std::string> out;
  const toml::array& a = r.array(n, key, key);
  for (size_t k = 0; k < a.size(); ++k) {
    const toml::node& e = *a.get(k);
    const std::string s = one_of(r, e, key, key, allowed, what);
    if (std::find(out.begin(), out.end(), s) != out.end())
      r.fail(line_of(&e), key, what + " \"" + s + "\" is listed twice", "list it once");
    out.push_back(s);
  }
  return out;
}

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
    for (const KeyInfo& k : kKeys)
      if (!starts_with(k.key, "body.") && !starts_with(k.key, "expect.body."))
        flat.push_back(k.key);
    if (std::find(flat.begin(), flat.end(), key) == flat.end()) {
      std::vector<std::string> all;
      for (const KeyInfo& k : kKeys) all.push_back(k.key);
      r.fail(0, "--set " + key, "unknown key", "did you mean " + nearest(key, all) + "?");
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

void read_sim(const Reader& r, const toml::table& sim, SimSettings& s, bool force) {
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
  if (const toml::node* n = get("sweep_dt")) {
    const toml::array& a = r.array(*n, "sim.sweep_dt", "sim.sweep_dt");
    for (size_t k = 0; k < a.size(); ++k) {
      const std::string key = "sim.sweep_dt[" + std::to_string(k) + "]";
      const double dt = r.number(*a.get(k), key, "sim.sweep_dt");
      if (!(dt > 0))
        r.fail(line_of(a.get(k)), key, "time step must be > 0 s, got " + num(dt),
               "write e.g. sweep_dt = [1e-2, 1e-3, 1e-4]");
      s.sweep_dt.push_back(dt);
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
  // Blamed key: a sweep entry for its own step; for sim.dt, the duration when the file sets it
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
  if (const toml::node* n = sim.get("sweep_dt"))
    for (size_t k = 0; k < s.sweep_dt.size(); ++k)
      refuse(s.sweep_dt[k], "sim.sweep_dt[" + std::to_string(k) + "]", n->as_array()->get(k));
}

// Builds one body from its [[body]] table; mesh paths are resolved against `folder`.
BodySpec read_body(const Reader& r, const toml::table& t, const fs::path& folder,
                   std::vector<std::string>& notes) {
  BodySpec b;
  const int table_line = line_of(&t);

  // Name first: every other message names the body by it.
  const toml::node* name_node = t.get("name");
  if (!name_node)
    r.fail(table_line, "body.name", "this [[body]] has no name",
           "add name = \"...\" (unique within the scene)");
  b.name = r.string(*name_node, "body.name", "body.name");
  if (b.name.empty())
    r.fail(line_of(name_node), "body.name", "the name is empty", "give the body a unique name");
  const std::string p = "body." + b.name + ".";

  r.check_keys(t, p, keys_under("body."), false);

  // Shape, then keys that belong to other shapes.
  if (const toml::node* n = t.get("shape"))
    b.shape_kind =
        *shape_kind_from_string(one_of(r, *n, p + "shape", "body.shape", kShapes, "shape"));
  for (const auto& [key, node] : in_file_order(t)) {
    std::vector<std::string> owners;  // shapes that take this key (none: any shape)
    for (const auto& [k, shape] : kShapeKeys)
      if (k == key) owners.push_back(shape);
    if (!owners.empty() &&
        std::find(owners.begin(), owners.end(), to_string(b.shape_kind)) == owners.end())
      r.fail(key_line(t, key), p + key,
             "only valid for shape = \"" + join_quoted(owners) + "\", but this body's shape is \"" +
                 to_string(b.shape_kind) + "\"",
             "remove it, or set shape = \"" + owners.front() + "\"");
  }

  // Shape-specific values (defaults: box 1 m cube, icosphere r 0.5 with 2 subdivisions,
  // prism r 0.5, height 1, 6 sides).
  auto positive = [&](const char* key, double fallback, const char* what) {
    const toml::node* n = t.get(key);
    if (!n) return fallback;
    const double v = r.number(*n, p + key, std::string("body.") + key);
    if (!(v > 0))
      r.fail(line_of(n), p + key, std::string(what) + " must be > 0 m, got " + num(v),
             std::string("write e.g. ") + key + " = " + example_of(std::string("body.") + key));
    // Beyond the range, squared lengths and volumes overflow or underflow (kMaxLength).
    if (!(v >= kMinLength && v <= kMaxLength))
      r.fail(line_of(n), p + key, std::string(what) + " must be in [1e-12, 1e12] m, got " + num(v),
             std::string("give it in metres, e.g. ") + key + " = " +
                 example_of(std::string("body.") + key));
    return v;
  };
  auto shape_line = [&]() { return t.get("shape") ? line_of(t.get("shape")) : table_line; };
  try {
    if (b.shape_kind == ShapeKind::Box) {
      if (const toml::node* n = t.get("size")) {
        b.box_size = r.vec3(*n, p + "size", "body.size");
        if (!(b.box_size.minCoeff() > 0))
          r.fail(line_of(n), p + "size", "every extent must be > 0 m, got " + vec_text(b.box_size),
                 "write full extents, e.g. size = [1, 1, 1]");
        // Beyond the range, squared lengths and volumes overflow or underflow (kMaxLength).
        if (!(b.box_size.minCoeff() >= kMinLength && b.box_size.maxCoeff() <= kMaxLength))
          r.fail(line_of(n), p + "size",
                 "every extent must be in [1e-12, 1e12] m, got " + vec_text(b.box_size),
                 "give full extents in metres, e.g. size = [1, 1, 1]");
      }
      b.shape = std::make_shared<const ConvexPolyhedron>(make_box(b.box_size));
    } else if (b.shape_kind == ShapeKind::Icosphere) {
      const double radius = positive("radius", 0.5, "radius");
      long subdivisions = 2;
      if (const toml::node* n = t.get("subdivisions")) {
        subdivisions = r.integer(*n, p + "subdivisions", "body.subdivisions");
        if (subdivisions < 0 || subdivisions > 6)
          r.fail(line_of(n), p + "subdivisions",
                 "must be in 0..6, got " + std::to_string(subdivisions),
                 "6 already gives 81920 triangles, and 2 (320 triangles) is the default");
      }
      b.shape = std::make_shared<const ConvexPolyhedron>(
          make_icosphere(radius, static_cast<int>(subdivisions)));
    } else if (b.shape_kind == ShapeKind::Prism) {
      const double radius = positive("radius", 0.5, "radius");
      const double height = positive("height", 1.0, "height");
      long sides = 6;
      if (const toml::node* n = t.get("sides")) {
        sides = r.integer(*n, p + "sides", "body.sides");
        if (sides < 3 || sides > 100000)
          r.fail(line_of(n), p + "sides", "must be in 3..100000, got " + std::to_string(sides),
                 "use 3 (a triangular prism) or more, up to 100000");
      }
      b.shape = std::make_shared<const ConvexPolyhedron>(
          make_prism(radius, height, static_cast<int>(sides)));
    } else if (b.shape_kind == ShapeKind::Convex) {
      const toml::node* n = t.get("vertices");
      if (!n)
        r.fail(table_line, p + "vertices", "missing for shape = \"convex\"",
               "add vertices = [[x, y, z], ...] (at least 4 points spanning a volume)");
      const toml::array& a = r.array(*n, p + "vertices", "body.vertices");
      std::vector<Vec3> points;
      for (size_t k = 0; k < a.size(); ++k) {
        const std::string key = p + "vertices[" + std::to_string(k) + "]";
        points.push_back(r.vec3(*a.get(k), key, "body.vertices"));
        // Coordinates beyond kMaxLength overflow squared lengths and volumes.
        if (!(points.back().cwiseAbs().maxCoeff() <= kMaxLength))
          r.fail(line_of(a.get(k)), key,
                 "coordinates must be within 1e12 m of the origin, got " + vec_text(points.back()),
                 "give local coordinates in metres");
      }
      try {
        b.shape = std::make_shared<const ConvexPolyhedron>(convex_hull(points));
      } catch (const GeometryError& e) {
        r.fail(line_of(n), p + "vertices", e.what(),
               "give at least 4 points that are not all in one plane");
      }
    } else {  // mesh
      const toml::node* n = t.get("file");
      if (!n)
        r.fail(table_line, p + "file", "missing for shape = \"mesh\"",
               "add file = \"meshes/part.obj\" (relative to the scene's folder)");
      const std::string file = r.string(*n, p + "file", "body.file");
      bool hull = false;
      if (const toml::node* h = t.get("hull")) hull = r.boolean(*h, p + "hull", "body.hull");
      const std::string scene_folder = folder.empty() ? std::string(".") : folder.string();
      if (file.empty())
        r.fail(line_of(n), p + "file", "the path is empty",
               "name an OBJ file, relative to the scene's folder (" + scene_folder + ")");
      const fs::path resolved = fs::path(file).is_absolute() ? fs::path(file) : folder / file;
      std::error_code ec;
      if (!fs::exists(resolved, ec))
        r.fail(line_of(n), p + "file", "mesh file " + resolved.string() + " not found",
               "paths are relative to the scene's folder (" + scene_folder + ")");
      if (fs::is_directory(resolved, ec))
        r.fail(line_of(n), p + "file", resolved.string() + " is a folder, not an OBJ file",
               "name the .obj file (paths are relative to the scene's folder)");
      try {
        b.shape = std::make_shared<const ConvexPolyhedron>(load_obj(resolved.string(), hull));
      } catch (const ObjReadError& e) {
        // Not readable as OBJ text: the error says what would help (hull = true would not).
        r.fail(line_of(n), p + "file", e.what(), e.fix());
      } catch (const GeometryError& e) {
        std::string what = e.what();
        const std::string hint = " (use hull = true for its convex hull)";
        if (const size_t at = what.find(hint); at != std::string::npos) what.erase(at, hint.size());
        r.fail(line_of(n), p + "file", what,
               hull
                   ? "fix the OBJ file: its vertices must span a volume"
                   : "fix the OBJ file, or set hull = true to use the convex hull of its vertices");
      }
    }
  } catch (const GeometryError& e) {
    // The engine's own checks, should a value pass ours.
    r.fail(shape_line(), p + "shape", e.what(), "fix the shape's parameters");
  }

  // Mass and mass model.
  if (const toml::node* n = t.get("mass")) {
    b.mass = r.number(*n, p + "mass", "body.mass");
    if (!(b.mass > 0))
      r.fail(line_of(n), p + "mass", "must be > 0 kg, got " + num(b.mass),
             "give a positive mass (static = true makes a body immovable)");
  }
  if (const toml::node* n = t.get("static"))
    b.is_static = r.boolean(*n, p + "static", "body.static");
  if (const toml::node* n = t.get("mass_model"))
    b.mass_model = one_of(r, *n, p + "mass_model", "body.mass_model", {"solid", "vertices"},
                          "mass model") == "solid"
                       ? MassModel::Solid
                       : MassModel::Vertices;

  // Pose: rotation (degrees, R = Rz Ry Rx) or a unit quaternion, not both.
  if (const toml::node* n = t.get("position"))
    b.position = r.vec3(*n, p + "position", "body.position");
  const toml::node* rotation = t.get("rotation");
  const toml::node* orientation = t.get("orientation");
  if (rotation && orientation) {
    const bool rotation_last = line_of(rotation) > line_of(orientation);
    r.fail(line_of(rotation_last ? rotation : orientation),
           p + (rotation_last ? "rotation" : "orientation"),
           "both rotation and orientation are given", "keep one of them");
  }
  if (rotation) {
    const Vec3 deg = r.vec3(*rotation, p + "rotation", "body.rotation");
    b.orientation = Quat(rotation_from_euler_deg(deg)).normalized();
  }
  if (orientation) {
    const std::vector<double> q =
        r.numbers(*orientation, p + "orientation", "body.orientation", {"w", "x", "y", "z"});
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(std::abs(norm - 1.0) <= kUnitQuaternionTolerance))
      r.fail(line_of(orientation), p + "orientation",
             "quaternion [w, x, y, z] has norm " + fixed10(norm) + ", must be 1 within 1e-6",
             "write its components to at least 7 significant digits, or use rotation (degrees)");
    // Renormalise the (at most 1e-6) rounding, and say so where it is more than round-off.
    b.orientation = Quat(q[0], q[1], q[2], q[3]).normalized();
    if (std::abs(norm - 1.0) > 1e-12)
      notes.push_back(p + "orientation: norm " + fixed10(norm) + " normalised to 1");
  }
  if (const toml::node* n = t.get("velocity"))
    b.velocity = r.vec3(*n, p + "velocity", "body.velocity");
  if (const toml::node* n = t.get("angular_velocity"))
    b.angular_velocity = r.vec3(*n, p + "angular_velocity", "body.angular_velocity");
  return b;
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
  // A closed form the custom engine is known to miss (a documented limitation): kept as the
  // truth, reported as known, and pinned by the tests so a fix is noticed.
  if (const toml::node* n = t.get("known_failure")) {
    e.known_failure = r.string(*n, "expect.known_failure", "expect.known_failure");
    // It excuses the engine it names: without the name it would excuse nothing, silently.
    if (!starts_with(e.known_failure, "custom: ") && !starts_with(e.known_failure, "custom-seed: "))
      r.fail(line_of(n), "expect.known_failure",
             "must start with the engine it excuses, \"custom: \" or \"custom-seed: \"",
             "write e.g. known_failure = \"custom: why it fails here\"");
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

  // [expect.contact]: between the first two bodies at t = 0.
  if (const toml::node* n = t.get("contact")) {
    const toml::table& c = r.table(*n, "expect.contact");
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
    e.contact = ec;
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

const std::vector<std::string>& scene_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> out;
    for (const KeyInfo& k : kKeys) out.push_back(k.key);
    return out;
  }();
  return keys;
}

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
    read_sim(r, r.table(*n, "sim"), scene.sim, force);
  else
    read_sim(r, toml::table{}, scene.sim, force);

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
  // [expect] is the closed form of the physics the file describes: an override of that physics
  // (a body, gravity, restitution, friction, the duration it is judged at) sets it aside, to be
  // reported as not checked with the key that changed it. A step size, the integrator, the
  // checks, the backends or the expectation itself leave it standing.
  static const std::vector<std::string> kKeepExpect = {
      "sim.dt", "sim.sweep_dt", "sim.integrator", "sim.max_energy_ratio", "name", "description",
      "checks", "backends",     "force"};
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
