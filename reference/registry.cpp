// The backend registry: one line per backend, readable at a glance.
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
    case Status::Ok: return "ok";
    case Status::Error: return "error";
    case Status::Unsupported: return "unsupported";
  }
  return "error";
}

const std::vector<Backend>& backends() {
  // name, description, contact query, dynamics run.
  static const std::vector<Backend> table = {
      {"custom", "rbx engine: Moore & Wilhelms face/vertex/edge tests, single-point impulse",
       custom_contact, custom_dynamics},
      {"custom-seed", "rbx engine, the seed's algorithm: first hit, single-point frictionless impulse",
       nullptr, custom_seed_dynamics},
      {"exact", "rbx oracle: separating-axis test over faces and edge pairs, clipped manifold",
       exact_contact, nullptr},
      {"fcl", "FCL 0.7 Convex, GST_LIBCCD (libccd MPR)", fcl_contact, nullptr, fcl_mass},
      {"fcl-epa", "FCL 0.7 signed distance (GJK + EPA)", fcl_epa_contact, nullptr},
      {"fcl-indep", "FCL 0.7 Convex, GST_INDEP (known defects shown)", fcl_indep_contact, nullptr},
      {"fcl-box", "FCL 0.7 Box-Box (boxBoxIntersect, from ODE)", fcl_box_contact, nullptr},
      {"libccd", "libccd 2.1 on our support function: MPR and GJK + EPA", libccd_contact, nullptr},
      {"bullet", "Bullet 3.24 double: zero-margin hull GJK + EPA; btDiscreteDynamicsWorld",
       bullet_contact, bullet_dynamics, bullet_mass},
      {"bullet-sat", "Bullet 3.24 double: polyhedral SAT + clipping", bullet_sat_contact, nullptr},
      {"mujoco", "MuJoCo 2.2.2 mesh geoms (MPR); mj_step, restitution via negative solref",
       mujoco_contact, mujoco_dynamics, mujoco_mass},
      {"ode", "ODE 0.16.2 dCreateConvex; dWorldStep with bounce = e", ode_contact, ode_dynamics},
  };
  return table;
}

const Backend* find_backend(const std::string& name) {
  for (const Backend& b : backends())
    if (b.name == name) return &b;
  return nullptr;
}

std::vector<RigidBody> make_bodies(const Scene& scene) {
  std::vector<RigidBody> bodies;
  bodies.reserve(scene.bodies.size());
  for (const BodySpec& spec : scene.bodies) bodies.push_back(make_body(spec));
  return bodies;
}

}  // namespace rbx
