// The backend registry: every adapter's rows (reference/<library>.cpp), in report order.
#include <algorithm>
#include <stdexcept>

#include "reference/backend.h"
#include "reference/bullet.h"
#include "reference/custom.h"
#include "reference/dart.h"
#include "reference/exact.h"
#include "reference/fcl.h"
#include "reference/libccd.h"
#include "reference/mujoco.h"
#include "reference/ode.h"

namespace rbx {

const char* to_string(Status s) {
  switch (s) {
    case Status::Ok:
      return "ok";
    case Status::Error:
      return "error";
    case Status::Unsupported:
      return "unsupported";
    case Status::Timeout:
      return "timeout";
    case Status::Touching:
      return "touching";
  }
  return "error";
}

namespace {

// Every adapter, in report order: our engine and oracle, then the libraries.
std::vector<const Adapter*> adapters() {
  return {&custom_adapter(), &exact_adapter(),  &fcl_adapter(), &libccd_adapter(),
          &bullet_adapter(), &mujoco_adapter(), &ode_adapter(), &dart_adapter()};
}

std::vector<Backend>& registry_table() {
  // Plain names: the library as its experts use it (native primitives where a body is one);
  // `-hull`: every body the same convex hull the custom engine gets.
  static std::vector<Backend> table = [] {
    std::vector<Backend> rows;
    for (const Adapter* a : adapters())
      rows.insert(rows.end(), a->backends.begin(), a->backends.end());
    return rows;
  }();
  return table;
}

}  // namespace

const std::vector<Backend>& backends() { return registry_table(); }

void register_backend(Backend b) {
  if (b.name.empty() || b.name.find_first_of(", \t\n") != std::string::npos)
    throw std::invalid_argument("backend name '" + b.name +
                                "': one word without commas or spaces, please");
  if (!b.contact && !b.dynamics)
    throw std::invalid_argument("backend '" + b.name + "' has neither contact nor dynamics");
  b.user = true;
  for (Backend& have : registry_table()) {
    if (have.name != b.name) continue;
    if (!have.user)
      throw std::invalid_argument("backend name '" + b.name + "' is a built-in backend's");
    // Registered again (a notebook's edit and rerun): the new one replaces it, in its place.
    have = std::move(b);
    return;
  }
  registry_table().push_back(std::move(b));
}

void unregister_backend(const std::string& name) {
  std::vector<Backend>& table = registry_table();
  const auto it =
      std::find_if(table.begin(), table.end(), [&](const Backend& b) { return b.name == name; });
  if (it == table.end())
    throw std::invalid_argument("no backend named '" + name + "' to unregister");
  if (!it->user)
    throw std::invalid_argument("backend '" + name + "' is built in; only registered ones go");
  table.erase(it);
}

const Backend* find_backend(const std::string& name) { return find_backend(name, nullptr); }

const Backend* find_backend(const std::string& name, const std::vector<Backend>* table) {
  for (const Backend& b : table ? *table : backends())
    if (b.name == name) return &b;
  return nullptr;
}

const std::vector<QueryVariant>& query_variants() {
  static const std::vector<QueryVariant> table = [] {
    std::vector<QueryVariant> rows;
    for (const Adapter* a : adapters())
      rows.insert(rows.end(), a->variants.begin(), a->variants.end());
    return rows;
  }();
  return table;
}

const QueryVariant* find_query_variant(const std::string& backend, const std::string& variant) {
  for (const QueryVariant& v : query_variants())
    if (v.backend == backend && v.variant == variant) return &v;
  return nullptr;
}

}  // namespace rbx
