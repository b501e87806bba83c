// The backend registry: one line per backend, readable at a glance.
#include <stdexcept>

#include "reference/backend.h"
#include "reference/bullet.h"
#include "reference/custom.h"
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

std::vector<Backend>& registry_table() {
  // name, description, contact query, dynamics run, mass properties, library (isolated).
  // Plain names: the library as its experts use it (native primitives where a body is one);
  // `-hull`: every body the same convex hull the custom engine gets. The former `fcl-box`
  // (Box-Box only) is what `fcl` runs on two boxes, so it is gone as a duplicate.
  static std::vector<Backend> table = {
      {"custom",
       "rbx engine, extended: Moore & Wilhelms tests with the plane of least overlap, contact "
       "manifolds, Coulomb friction, resting contact, time of impact for every new contact",
       custom_contact, custom_dynamics, nullptr, false},
      {"custom-seed",
       "rbx engine, the seed's algorithm: first hit, single-point frictionless impulse", nullptr,
       custom_seed_dynamics, nullptr, false, false},
      {"exact", "rbx oracle: separating-axis test over faces and edge pairs, clipped manifold",
       exact_contact, nullptr, nullptr, false},
      {"fcl", "FCL 0.7: Box (boxBoxIntersect) or Convex (libccd MPR)", fcl_contact, nullptr,
       fcl_mass},
      {"fcl-hull", "FCL 0.7 Convex, GST_LIBCCD (libccd MPR)", fcl_hull_contact, nullptr,
       fcl_hull_mass},
      {"fcl-epa", "FCL 0.7 signed distance (GJK + EPA)", fcl_epa_contact, nullptr},
      {"fcl-indep", "FCL 0.7 Convex, GST_INDEP (known defects shown)", fcl_indep_contact, nullptr},
      {"libccd-mpr", "libccd 2.1 MPR (ccdMPRPenetration); libccd's box support for boxes",
       libccd_mpr_contact, nullptr},
      {"libccd-epa", "libccd 2.1 GJK + EPA (ccdGJKPenetration); libccd's box support for boxes",
       libccd_epa_contact, nullptr},
      {"bullet", "Bullet 3.24 double: btBoxShape or polyhedral hull (clipped); fair world",
       bullet_contact, bullet_dynamics, bullet_mass},
      {"bullet-hull", "Bullet 3.24 double: zero-margin hull GJK + EPA; fair world",
       bullet_hull_contact, bullet_hull_dynamics, bullet_hull_mass},
      {"bullet-sat", "Bullet 3.24 double: polyhedral hull SAT + clipping, boxes too",
       bullet_sat_contact, nullptr},
      {"mujoco", "MuJoCo 2.2.2 box geoms (box-box) or mesh + multiccd; mj_step, negative solref",
       mujoco_contact, mujoco_dynamics, mujoco_mass},
      {"mujoco-hull", "MuJoCo 2.2.2 mesh geoms (MPR, one point); mj_step, negative solref",
       mujoco_hull_contact, mujoco_hull_dynamics, mujoco_hull_mass},
      {"ode", "ODE 0.16.2 dCreateBox (dBoxBox) or dCreateConvex; dWorldStep, bounce = e",
       ode_contact, ode_dynamics},
      {"ode-hull", "ODE 0.16.2 dCreateConvex (libccd MPR); dWorldStep, bounce = e",
       ode_hull_contact, ode_hull_dynamics},
  };
  return table;
}

}  // namespace

const std::vector<Backend>& backends() { return registry_table(); }

void register_backend(Backend b) {
  if (b.name.empty() || b.name.find_first_of(", \t\n") != std::string::npos)
    throw std::invalid_argument("backend name '" + b.name +
                                "': one word without commas or spaces, please");
  if (find_backend(b.name)) throw std::invalid_argument("backend name '" + b.name + "' is taken");
  if (!b.contact && !b.dynamics)
    throw std::invalid_argument("backend '" + b.name + "' has neither contact nor dynamics");
  b.user = true;
  registry_table().push_back(std::move(b));
}

const Backend* find_backend(const std::string& name) { return find_backend(name, nullptr); }

const Backend* find_backend(const std::string& name, const std::vector<Backend>* table) {
  for (const Backend& b : table ? *table : backends())
    if (b.name == name) return &b;
  return nullptr;
}

const std::vector<QueryVariant>& query_variants() {
  // backend, variant, what differs, contact query.
  static const std::vector<QueryVariant> table = {
      {"custom", "faithful",
       "custom on the faithful detector: the seed's loops over every primitive (the "
       "accelerated detector's oracle), the same chosen plane",
       custom_faithful_contact},
      {"fcl", "prebuilt",
       "each fcl::Box or Convex built once and kept, as a user holding FCL "
       "objects",
       fcl_contact_prebuilt},
      {"fcl-hull", "prebuilt", "each fcl::Convex built once and kept", fcl_hull_contact_prebuilt},
      {"bullet", "prebuilt", "each btBoxShape or polyhedral hull built once and kept",
       bullet_contact_prebuilt},
      {"bullet-hull", "prebuilt", "each btConvexHullShape built once and kept",
       bullet_hull_contact_prebuilt},
      {"bullet-sat", "prebuilt", "each polyhedral hull built once and kept",
       bullet_sat_contact_prebuilt},
      {"ode", "prebuilt", "each dBox or dConvex geom built once and kept", ode_contact_prebuilt},
      {"ode-hull", "prebuilt", "each dConvex geom built once and kept", ode_hull_contact_prebuilt},
      {"mujoco", "prebuilt", "the pair's model compiled once and kept (poses set, mj_forward)",
       mujoco_contact_prebuilt},
      {"mujoco-hull", "prebuilt", "the pair's model compiled once and kept",
       mujoco_hull_contact_prebuilt},
  };
  return table;
}

const QueryVariant* find_query_variant(const std::string& backend, const std::string& variant) {
  for (const QueryVariant& v : query_variants())
    if (v.backend == backend && v.variant == variant) return &v;
  return nullptr;
}

}  // namespace rbx
