#include "comparisons/eval/select_backends.h"

#include <algorithm>
#include <sstream>

#include "comparisons/scene/scene_file.h"

namespace rbx {

namespace {

bool serves(const Backend& b, Capability cap) {
  switch (cap) {
    case Capability::Contact:
      return static_cast<bool>(b.contact);
    case Capability::Dynamics:
      return static_cast<bool>(b.dynamics);
    case Capability::Distance:
      return static_cast<bool>(b.distance);
    case Capability::Toi:
      return static_cast<bool>(b.toi);
  }
  return false;
}

}  // namespace

std::vector<std::string> split_list(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream s(list);
  std::string item;
  while (std::getline(s, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::vector<std::string> select_backends(const Scene& scene, const std::string& list,
                                         Capability cap) {
  return select_backends(scene, list, cap, backends());
}

std::vector<std::string> parse_backend_list(const std::string& list,
                                            const std::vector<Backend>& table) {
  std::vector<std::string> out;
  if (list == "all") {
    for (const Backend& b : table) out.push_back(b.name);
    return out;
  }
  for (const std::string& name : split_list(list)) {
    if (std::none_of(table.begin(), table.end(),
                     [&](const Backend& b) { return b.name == name; })) {
      std::string names;
      for (const Backend& b : table) names += (names.empty() ? "" : ", ") + b.name;
      throw InputError("--backends: unknown backend '" + name + "'; known: all, " + names);
    }
    out.push_back(name);
  }
  return out;
}

std::vector<std::string> select_backends(const Scene& scene, const std::string& list,
                                         Capability cap, const std::vector<Backend>& table) {
  std::vector<std::string> wanted;
  if (list == "all") {
    for (const Backend& b : table)
      if (serves(b, cap)) wanted.push_back(b.name);
  } else if (!list.empty()) {
    wanted = parse_backend_list(list, table);
  } else if (!scene.backends.empty()) {
    wanted = scene.backends;
  }
  // Table order; a backend named explicitly stays even if it cannot serve (-> unsupported).
  std::vector<std::string> out;
  for (const Backend& b : table) {
    const bool named = std::find(wanted.begin(), wanted.end(), b.name) != wanted.end();
    if (wanted.empty() ? serves(b, cap) : named) out.push_back(b.name);
  }
  return out;
}

}  // namespace rbx
