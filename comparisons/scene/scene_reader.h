// Internal to comparisons/scene/: what the scene-file readers share (scene_file.cpp reads the
// file and its overrides, scene_body.cpp a [[body]]): the format's key table, the typed value
// reader whose every failure is one line naming the file, line and key, and text helpers.
#pragma once

#include <toml++/toml.h>

#include <filesystem>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "comparisons/scene/scene_file.h"
#include "engine/math.h"

namespace rbx::scene_detail {

inline const std::vector<std::string> kChecks = {"contact", "impulse", "trajectory", "stability",
                                                 "mass"};
inline const std::vector<std::string> kBackends = {
    "custom",    "custom-seed", "exact",      "fcl",      "fcl-hull",    "fcl-epa",
    "fcl-indep", "libccd-mpr",  "libccd-epa", "bullet",   "bullet-hull", "bullet-sat",
    "mujoco",    "mujoco-hull", "ode",        "ode-hull", "dart",        "dart-hull"};

inline const std::vector<std::string> kShapes = {"box", "icosphere", "prism", "convex", "mesh"};

// Shape-specific body keys and the shape that owns them.
inline const std::vector<std::pair<std::string, std::string>> kShapeKeys = {
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

// Source name of values parsed from --set: they have no line in the scene file.
constexpr std::string_view kOverrideSource = "--set";

/// Keys of the sub-tables of one level of the format: prefix "sim." -> {"dt", ...}.
std::vector<std::string> keys_under(const std::string& prefix);
/// The example value of a key for messages ("write e.g. mass = 1.0"); "..." when none.
const char* example_of(const std::string& generic);
/// True when `s` begins with `prefix`.
bool starts_with(const std::string& s, const std::string& prefix);
/// The candidate nearest to `word` (edit distance; ties to the longer common prefix, then the
/// first listed), for "did you mean".
std::string nearest(const std::string& word, const std::vector<std::string>& candidates);
/// "a\" or \"b": for "shape = \"icosphere\" or \"prism\"".
std::string join_quoted(const std::vector<std::string>& words);
/// "a, b, c".
std::string join(const std::vector<std::string>& words);
/// Shortest decimal that reads back as the same double; below a million, all integer digits.
std::string num(double v);
/// Ten significant digits: enough to show how far from 1 a norm is.
std::string fixed10(double v);
/// "[x, y, z]" of num()s.
std::string vec_text(const Vec3& v);
/// What a TOML value is, for "expected X, got Y" messages.
std::string describe(const toml::node& n);
/// Line breaks replaced, so that a message stays one line.
std::string one_line(std::string s);
/// Entries of a table in file order (toml++ keeps them sorted by key), so that the first
/// offending line of the file is the one reported.
std::vector<std::pair<std::string, const toml::node*>> in_file_order(const toml::table& t);
/// Line of a key within its table (0 if unknown).
int key_line(const toml::table& t, const std::string& key);
/// Line of a value in the scene file (0 if none, as for values from --set).
int line_of(const toml::node* n);

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
    // Keys an older rbx read, by the name that replaced them: a scene written for it gets the
    // new name, not a guess.
    static const std::pair<const char*, const char*> kRenamed[] = {
        {"sim.sweep_dt", "sim.dt_study"}};
    for (const auto& [key, node] : in_file_order(t)) {
      if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
      for (const auto& [old_key, new_key] : kRenamed)
        if (prefix + key == old_key)
          fail(key_line(t, key), prefix + key, "renamed",
               "write " + std::string(new_key) + " (the same value)");
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

/// A name from a fixed list, with "did you mean" for anything else.
std::string one_of(const Reader& r, const toml::node& n, const std::string& key,
                   const std::string& generic, const std::vector<std::string>& allowed,
                   const std::string& what);
/// A list of names from a fixed list (checks, backends), no repeats.
std::vector<std::string> names_from(const Reader& r, const toml::node& n, const std::string& key,
                                    const std::vector<std::string>& allowed,
                                    const std::string& what);

/// Builds one body from its [[body]] table; mesh paths are resolved against `folder`; notes on
/// accepted input (a renormalised quaternion) go to `notes`.
BodySpec read_body(const Reader& r, const toml::table& t, const std::filesystem::path& folder,
                   std::vector<std::string>& notes);

}  // namespace rbx::scene_detail
