#include "comparisons/scene/scene_reader.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "engine/format.h"

namespace rbx::scene_detail {

namespace {

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
    {"sim.dt_study", "[1e-2, 1e-3, 1e-4]"},
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
    {"expect.truth", "\"analytic\""},
    {"expect.engines", "[\"custom\", \"custom-seed\"]"},
    {"expect.known_failure", "\"no resting contact (seed correction 12)\""},
    {"expect.body.position", "[0, 0, 0]"},
    {"expect.body.velocity", "[0, 0, 0]"},
    {"expect.body.angular_velocity", "[0, 0, 0]"},
    {"expect.contact.touching", "true"},
    {"expect.contact.normal", "[-1, 0, 0]"},
    {"expect.contact.either_sign", "true"},
    {"expect.contact.depth", "0.1"},
    {"expect.contact.point", "[0, 0, 0]"},
    {"expect.contact.patch", "[[0, -0.5, 0], [0, 0.5, 0]]"},
    {"expect.distance.overlapping", "false"},
    {"expect.distance.distance", "0.25"},
    {"expect.toi.touch", "true"},
    {"expect.toi.fraction", "0.5"},
    {"ensemble.count", "50"},
    {"ensemble.step_test", "true"},
    {"ensemble.duration", "0.5"},
};

}  // namespace

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

// Line of a value in the scene file (0 if none, as for values from --set).
int line_of(const toml::node* n) {
  if (!n) return 0;
  const toml::source_region& src = n->source();
  if (src.path && *src.path == kOverrideSource) return 0;
  return static_cast<int>(src.begin.line);
}

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

}  // namespace rbx::scene_detail

namespace rbx {

const std::vector<std::string>& scene_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> out;
    for (const scene_detail::KeyInfo& k : scene_detail::kKeys) out.push_back(k.key);
    return out;
  }();
  return keys;
}

}  // namespace rbx
