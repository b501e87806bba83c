// MuJoCo 2.2.2 adapter: every body becomes a free-joint body holding one geom; static bodies
// become geoms of the world body. `mujoco-hull`: every geom a mesh of the body-frame hull (MPR,
// one contact point per pair). `mujoco` (MujocoSettings, each choice measured in
// tests/reference/fair_settings_test.cpp): box geoms when every body of the model is a box (so
// every pair meets in mjc_BoxBox, several points), with the contact stiffness doubled for the
// dynamics because 2.2.2's box-box collider reports half the depth; otherwise mesh geoms with
// multi-point convex collision (mjENBL_MULTICCD). Box geoms only when all are boxes: a box-mesh
// pair runs MPR at the full depth, so one global stiffness factor would be wrong for it.
// Contact queries of `mujoco` take the same geoms as its dynamics: MuJoCo's own box-box collider
// for two boxes (its halved depth passed on, labelled: no stiffness makes up for it in a query).
//
// The model is written as MJCF text into MuJoCo's virtual file system and compiled with
// mj_loadXML. Three MuJoCo habits need care:
//  - Mesh recentring: the compiler moves a mesh to its own centre of mass and principal axes
//    and compensates in geom_pos / geom_quat. Our bodies carry an explicit <inertial> at the
//    body origin (our centre of mass), so the mesh's own inertia is never used; after
//    compiling, check_geometry() maps every compiled vertex back to the body frame and
//    refuses the model if it does not land on our hull (to float precision: MuJoCo stores
//    mesh vertices as float).
//  - Errors: mju_error() calls exit() unless mju_user_error is set. Our handler longjmps back
//    to guarded() (MuJoCo's documented pattern); no C++ object with a non-trivial destructor
//    lives between setjmp and the MuJoCo call, so the jump skips only C frames and trivial
//    ones. Warnings (e.g. a non-finite state, after which mj_step silently resets the data)
//    are recorded and turned into Status::Error.
//  - No coefficient of restitution: contacts are soft. See restitution_damping_ratio().
#include "reference/mujoco.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <sstream>
#include <tuple>
#include <utility>

#include "engine/format.h"
#include "reference/c_error_trap.h"
#include "reference/dynamics_recorder.h"
#include "reference/mujoco_soft.h"
#include "reference/prebuilt_cache.h"

namespace {

// MuJoCo's error state on the calling thread (reference/c_error_trap.h).
thread_local rbx::CErrorTrap t_trap;

}  // namespace

extern "C" {

// mju_user_error: copy the message and jump back to guarded(). Outside guarded() there is no
// safe place to return to, so behave as MuJoCo would (print, terminate).
static void rbx_mujoco_on_error(const char* msg) {
  rbx::trap_printf(t_trap.error, "%s", msg ? msg : "");
  rbx::trap_jump_or_abort(t_trap, "MuJoCo error outside a guarded call: %s\n");
}

// mju_user_warning: keep the first message; the caller turns it into Status::Error.
static void rbx_mujoco_on_warning(const char* msg) {
  if (!t_trap.has_warning()) rbx::trap_printf(t_trap.warning, "%s", msg ? msg : "");
}

}  // extern "C"

namespace rbx {
namespace {

// Soft-contact duration in time steps (MujocoSettings::contact_steps, 25 unless a fit sets it):
// the stiffness is chosen so that an undamped contact lasts this many steps (see
// contact_stiffness()), whatever dt, so the integration stays stable and the
// time-discretisation error of one impact is fixed (measured at 25: 1e-4 in e at e = 1, e within
// 0.485..0.517 for a target of 0.5 depending on the entry phase) while the penetration, about
// v * 25 dt / pi, shrinks with dt.

// Installs our handlers (MuJoCo keeps them in two global function pointers).
void install_handlers() {
  mju_user_error = rbx_mujoco_on_error;
  mju_user_warning = rbx_mujoco_on_warning;
}

// Runs f() so that a MuJoCo error returns false (message in t_trap.error) instead of exiting.
// f must own no object with a non-trivial destructor (the longjmp skips its frame).
template <class F>
bool guarded(F&& f) {
  install_handlers();
  return rbx::guarded(t_trap, std::forward<F>(f));
}

// Owners of MuJoCo's C objects.
struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
struct VfsDeleter {
  void operator()(mjVFS* v) const {
    mj_deleteVFS(v);
    delete v;
  }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

// Contact parameters written into every geom.
struct ContactParams {
  double stiffness = 0.0;  // 1/s^2, per unit effective mass (solref = -stiffness)
  double damping = 0.0;    // 1/s, per unit effective mass (solref = -damping)
  double friction = 0.0;   // Coulomb mu; 0: frictionless (condim 1)
  double impedance = MujocoSettings{}.impedance;  // solimp dmin = dmax
};

// Model-level options.
struct ModelOptions {
  double dt = 1e-3;  // s
  Vec3 gravity = Vec3::Zero();
  ContactParams contact;
  bool box_geoms = false;  // box geoms for the (all box) bodies; false: mesh geoms
  bool multiccd = false;   // multi-point convex collision for mesh pairs
  bool elliptic_cone = false;
  double impratio = 1.0;
  int noslip_iterations = 0;
  double margin = 0.0;  // m, every geom's contact margin (distance queries: a contact within it)
};

// Prints a double so that it reads back exactly (17 significant digits).
std::string num(double x) {
  NumberFormat f;
  f.digits = 17;
  f.signed_zero = true;
  return format_number(x, f);
}

std::string vec_text(const Vec3& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

// MuJoCo quaternions are (w, x, y, z).
std::string quat_text(const Quat& q) {
  return num(q.w()) + " " + num(q.x()) + " " + num(q.y()) + " " + num(q.z());
}

// True when the model of `bodies` under `settings` uses box geoms: every body a native box.
bool use_box_geoms(const std::vector<RigidBody>& bodies, const MujocoSettings& settings) {
  if (!settings.box_geoms) return false;
  for (const RigidBody& b : bodies)
    if (!is_native_box(b)) return false;
  return true;
}

// Geom element attributes of body i's shape: a box of the body's half extents (centred on the
// body origin, by is_native_box) or its hull mesh.
std::string shape_attributes(const RigidBody& b, size_t i, bool box) {
  if (box) return " type=\"box\" size=\"" + vec_text(0.5 * b.box_size) + "\"";
  return " type=\"mesh\" mesh=\"hull" + std::to_string(i) + "\"";
}

// <mesh> of a body's hull in its body frame (vertices and the outward triangles).
std::string mesh_element(const std::string& name, const ConvexPolyhedron& hull) {
  std::ostringstream s;
  s << "<mesh name=\"" << name << "\" vertex=\"";
  for (const Vec3& v : hull.vertices()) s << vec_text(v) << "  ";
  s << "\" face=\"";
  for (const auto& t : hull.triangles()) s << t[0] << " " << t[1] << " " << t[2] << "  ";
  s << "\"/>\n";
  return s.str();
}

// The geom attributes shared by every body: frictionless unless asked, soft contact given
// directly as stiffness and damping (negative solref), constant impedance.
std::string geom_contact_attributes(const ContactParams& c) {
  std::ostringstream s;
  if (c.friction > 0.0)
    s << " condim=\"3\" friction=\"" << num(c.friction) << " 0 0\"";
  else
    s << " condim=\"1\"";
  s << " solref=\"" << num(-c.stiffness) << " " << num(-c.damping) << "\"";
  s << " solimp=\"" << num(c.impedance) << " " << num(c.impedance) << " 0.001 0.5 2\"";
  return s.str();
}

// MJCF of the bodies. Static bodies become world geoms unless `all_free` (contact queries,
// where two world geoms would never be tested against each other).
std::string build_mjcf(const std::vector<RigidBody>& bodies, bool all_free,
                       const ModelOptions& opt) {
  const size_t n = bodies.size();
  std::ostringstream s;
  s << "<mujoco model=\"rbx\">\n";
  s << "<compiler angle=\"radian\"/>\n";
  // MPR tolerance tightened from 1e-6 so that depths are limited by MuJoCo's float vertices,
  // not by the iteration stopping early.
  s << "<option timestep=\"" << num(opt.dt) << "\" gravity=\"" << vec_text(opt.gravity)
    << "\" integrator=\"Euler\" mpr_tolerance=\"1e-12\" mpr_iterations=\"500\""
    << " cone=\"" << (opt.elliptic_cone ? "elliptic" : "pyramidal") << "\" impratio=\""
    << num(opt.impratio) << "\" noslip_iterations=\"" << opt.noslip_iterations << "\">"
    << (opt.multiccd ? "<flag multiccd=\"enable\"/>" : "") << "</option>\n";
  // Contact buffers: 8 points per pair for small scenes; for many bodies, where a body touches
  // only its neighbours, 16 per body (8 per pair over all pairs of 100 bodies is more memory
  // than mj_makeData will allocate).
  const size_t pairs = std::max<size_t>(1, n * (n - 1) / 2);
  const size_t ncon = std::max<size_t>(100, std::min(8 * pairs, 16 * n));
  s << "<size nconmax=\"" << ncon << "\" njmax=\"" << 3 * ncon << "\"/>\n";
  s << "<asset>\n";
  if (!opt.box_geoms)
    for (size_t i = 0; i < n; ++i) s << mesh_element("hull" + std::to_string(i), *bodies[i].shape);
  s << "</asset>\n<worldbody>\n";
  const std::string contact =
      geom_contact_attributes(opt.contact) +
      (opt.margin > 0 ? " margin=\"" + num(opt.margin) + "\"" : std::string());
  for (size_t i = 0; i < n; ++i) {
    const RigidBody& b = bodies[i];
    const std::string shape = shape_attributes(b, i, opt.box_geoms);
    if (b.is_static && !all_free) {
      s << "<geom name=\"g" << i << "\"" << shape << " pos=\"" << vec_text(b.position)
        << "\" quat=\"" << quat_text(b.orientation) << "\"" << contact << "/>\n";
      continue;
    }
    // Body frame = our centre-of-mass frame; explicit inertia about it, in body axes.
    const Mat3& I = b.inertia_body;
    s << "<body name=\"b" << i << "\" pos=\"" << vec_text(b.position) << "\" quat=\""
      << quat_text(b.orientation) << "\">\n";
    s << "  <freejoint/>\n";
    s << "  <inertial pos=\"0 0 0\" mass=\"" << num(b.mass) << "\" fullinertia=\"" << num(I(0, 0))
      << " " << num(I(1, 1)) << " " << num(I(2, 2)) << " " << num(I(0, 1)) << " " << num(I(0, 2))
      << " " << num(I(1, 2)) << "\"/>\n";
    s << "  <geom name=\"g" << i << "\"" << shape << contact << "/>\n";
    s << "</body>\n";
  }
  s << "</worldbody>\n</mujoco>\n";
  return s.str();
}

// Compiles MJCF text through the virtual file system (no temporary file on disk).
ModelPtr load_model(const std::string& xml, std::string* error) {
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  const char* name = "rbx_model.xml";
  // Guarded: when its allocation fails, mj_makeEmptyFileVFS ends in mju_error (mju_malloc's
  // "Could not allocate memory"), not in its return code; unguarded, that ended the process
  // (found by the allocation-failure test in tests/reference/mujoco_test.cpp).
  mjVFS* const v = vfs.get();
  const int size = static_cast<int>(xml.size());
  int made = -1;
  if (!guarded([&] { made = mj_makeEmptyFileVFS(v, name, size); })) {
    *error = std::string("MuJoCo mj_makeEmptyFileVFS: ") + t_trap.error;
    return nullptr;
  }
  if (made != 0) {
    *error = "MuJoCo VFS: cannot create the model file";
    return nullptr;
  }
  const int idx = mj_findFileVFS(vfs.get(), name);
  std::memcpy(vfs->filedata[idx], xml.data(), xml.size());
  // Compiler errors come back in `buf` (the compiler installs its own handler while it runs).
  char buf[1024] = "";
  t_trap.clear_warning();
  install_handlers();
  ModelPtr m(mj_loadXML(name, vfs.get(), buf, sizeof(buf)));
  if (!m) *error = std::string("MuJoCo mj_loadXML: ") + buf;
  return m;
}

// Geom id of body i (geoms are named g<i>).
int geom_of(const mjModel* m, size_t i) {
  return mj_name2id(m, mjOBJ_GEOM, ("g" + std::to_string(i)).c_str());
}

// Checks that the compiled geom of every body sits where our hull is: each compiled vertex,
// mapped through geom_pos/geom_quat into the body frame (world frame for world geoms), must
// be one of our hull vertices. Returns an empty string, or what is wrong.
std::string check_geometry(const mjModel* m, const std::vector<RigidBody>& bodies) {
  for (size_t i = 0; i < bodies.size(); ++i) {
    const int g = geom_of(m, i);
    if (g < 0) return "geom g" + std::to_string(i) + " missing after compiling";
    const bool world = m->geom_bodyid[g] == 0;
    const RigidBody& b = bodies[i];
    if (m->geom_type[g] == mjGEOM_BOX) {
      // A box geom is stored in double and never recentred: its size and place must be ours.
      const Vec3 size(m->geom_size[3 * g], m->geom_size[3 * g + 1], m->geom_size[3 * g + 2]);
      const Vec3 pos(m->geom_pos[3 * g], m->geom_pos[3 * g + 1], m->geom_pos[3 * g + 2]);
      const Vec3 expected_pos = world ? b.position : Vec3::Zero();
      const double tol = 1e-12 * (b.box_size.norm() + expected_pos.norm());
      if ((size - 0.5 * b.box_size).norm() > tol || (pos - expected_pos).norm() > tol)
        return "box geom of " + b.name + " is not our box after compiling";
      continue;
    }
    const auto& hull = b.shape->vertices();
    const int mesh = m->geom_dataid[g];
    const int nv = m->mesh_vertnum[mesh];
    const float* vert = m->mesh_vert + 3 * m->mesh_vertadr[mesh];
    const Vec3 gpos(m->geom_pos[3 * g], m->geom_pos[3 * g + 1], m->geom_pos[3 * g + 2]);
    const Quat gq(m->geom_quat[4 * g], m->geom_quat[4 * g + 1], m->geom_quat[4 * g + 2],
                  m->geom_quat[4 * g + 3]);
    // Float storage: relative round-off 6e-8 of the mesh size, with margin.
    double size = 0.0;
    for (const Vec3& v : hull) size = std::max(size, v.norm());
    const double tol = 1e-6 * std::max(size, 1e-300) + (world ? 1e-6 * b.position.norm() : 0.0);
    if (nv != static_cast<int>(hull.size()))
      return "mesh of " + b.name + " has " + std::to_string(nv) + " vertices after compiling, " +
             std::to_string(hull.size()) + " given";
    for (int k = 0; k < nv; ++k) {
      const Vec3 local(vert[3 * k], vert[3 * k + 1], vert[3 * k + 2]);
      Vec3 p = gq.normalized() * local + gpos;
      if (world) p = b.orientation.conjugate() * (p - b.position);
      double best = INFINITY;
      for (const Vec3& h : hull) best = std::min(best, (h - p).norm());
      if (best > tol)
        return "compiled mesh of " + b.name + " is off our hull by " + num(best) +
               " m (mesh recentring not compensated)";
    }
  }
  return {};
}

// Builds model and data for the bodies, with the geometry check. Empty pointers and `error`
// set on failure.
std::pair<ModelPtr, DataPtr> make_simulation(const std::vector<RigidBody>& bodies, bool all_free,
                                             const ModelOptions& opt, std::string* error) {
  ModelPtr m = load_model(build_mjcf(bodies, all_free, opt), error);
  if (!m) return {};
  if (std::string bad = check_geometry(m.get(), bodies); !bad.empty()) {
    *error = "MuJoCo: " + bad;
    return {};
  }
  mjData* raw = nullptr;
  const mjModel* mc = m.get();
  if (!guarded([&] { raw = mj_makeData(mc); }) || !raw) {
    *error = std::string("MuJoCo mj_makeData: ") + t_trap.error;
    return {};
  }
  return {std::move(m), DataPtr(raw)};
}

// Sets qpos/qvel of every free body from our state (angular velocity into the body frame:
// a free joint's qvel[3:6] is in body coordinates).
void set_state(const mjModel* m, mjData* d, const std::vector<RigidBody>& bodies) {
  for (size_t i = 0; i < bodies.size(); ++i) {
    const int g = geom_of(m, i);
    const int body = m->geom_bodyid[g];
    if (body == 0) continue;
    const int jnt = m->body_jntadr[body];
    double* q = d->qpos + m->jnt_qposadr[jnt];
    double* v = d->qvel + m->jnt_dofadr[jnt];
    const RigidBody& b = bodies[i];
    const Quat o = b.orientation.normalized();
    const Vec3 w_body = o.conjugate() * b.angular_velocity;
    for (int k = 0; k < 3; ++k) {
      q[k] = b.position[k];
      v[k] = b.velocity[k];
      v[3 + k] = w_body[k];
    }
    q[3] = o.w();
    q[4] = o.x();
    q[5] = o.y();
    q[6] = o.z();
  }
}

// Final state of scene body i (static: its fixed pose, zero velocity).
BodyFinal read_state(const mjModel* m, const mjData* d, const RigidBody& b, size_t i) {
  BodyFinal f;
  f.name = b.name;
  const int body = m->geom_bodyid[geom_of(m, i)];
  if (body == 0) {
    f.position = b.position;
    f.orientation = b.orientation;
    return f;
  }
  const int jnt = m->body_jntadr[body];
  const double* q = d->qpos + m->jnt_qposadr[jnt];
  const double* v = d->qvel + m->jnt_dofadr[jnt];
  f.position = Vec3(q[0], q[1], q[2]);
  f.orientation = Quat(q[3], q[4], q[5], q[6]).normalized();
  f.velocity = Vec3(v[0], v[1], v[2]);
  // qvel[3:6] is in the body frame: rotate to the world.
  f.angular_velocity = f.orientation * Vec3(v[3], v[4], v[5]);
  return f;
}

// Our contact from MuJoCo's: frame[0:3] points from geom1 toward geom2 and dist < 0 when
// penetrating; ours points from B toward A with depth >= 0. So the normal is -frame when geom1
// belongs to A, +frame when it belongs to B.
ContactPoint convert_contact(const mjContact& c, bool geom1_is_a) {
  ContactPoint p;
  const Vec3 frame(c.frame[0], c.frame[1], c.frame[2]);
  p.normal = geom1_is_a ? Vec3(-frame) : frame;
  p.depth = -c.dist;
  p.point = Vec3(c.pos[0], c.pos[1], c.pos[2]);
  p.feature = "mesh";  // MuJoCo 2.2.2 mesh-mesh: MPR, one point
  return p;
}

// The library's own mass properties of a box geom (`box`) or of the hull mesh.
MassResult mass_of_geom(const RigidBody& body, bool box) {
  MassResult r;
  std::ostringstream xml;
  xml << "<mujoco model=\"rbx_mass\">\n<compiler inertiafromgeom=\"true\"/>\n<asset>\n"
      << (box ? "" : mesh_element("hull0", *body.shape)) << "</asset>\n<worldbody>\n"
      << "<body name=\"b\">\n<freejoint/>\n<geom" << shape_attributes(body, 0, box) << " mass=\""
      << num(body.mass) << "\"/>\n</body>\n</worldbody>\n</mujoco>\n";
  std::string error;
  ModelPtr m = load_model(xml.str(), &error);
  if (!m) return {Status::Error, error, 0.0, -1.0, Vec3::Zero(), Mat3::Zero()};
  const int b = 1;  // body 0 is the world
  r.mass = m->body_mass[b];
  r.center_of_mass = Vec3(m->body_ipos[3 * b], m->body_ipos[3 * b + 1], m->body_ipos[3 * b + 2]);
  const Quat q(m->body_iquat[4 * b], m->body_iquat[4 * b + 1], m->body_iquat[4 * b + 2],
               m->body_iquat[4 * b + 3]);
  const Vec3 moments(m->body_inertia[3 * b], m->body_inertia[3 * b + 1],
                     m->body_inertia[3 * b + 2]);
  const Mat3 rot = q.normalized().toRotationMatrix();
  r.inertia = rot * moments.asDiagonal() * rot.transpose();
  r.message = box ? "box geom, inertiafromgeom" : "mesh geom, inertiafromgeom";
  return r;
}

/// The settings of `mujoco` contact queries: those of its dynamics (box geoms for two boxes,
/// multiccd meshes otherwise; see mujoco_contact).
MujocoSettings mujoco_query_settings() { return MujocoSettings{}; }

}  // namespace

MujocoSettings mujoco_hull_settings() {
  MujocoSettings s;
  s.box_geoms = false;
  s.multiccd = false;
  return s;
}

namespace {

/// A compiled two-body model for contact queries (`error` set when it failed to build).
struct QueryModel {
  ModelPtr m;
  DataPtr d;
  ModelOptions opt;
  std::string error;
};

QueryModel make_query_model(const RigidBody& a, const RigidBody& b, const MujocoSettings& settings,
                            double margin = 0.0) {
  QueryModel q;
  const std::vector<RigidBody> bodies{a, b};
  q.opt.box_geoms = use_box_geoms(bodies, settings);
  q.opt.multiccd = settings.multiccd;
  q.opt.margin = margin;
  std::tie(q.m, q.d) = make_simulation(bodies, /*all_free=*/true, q.opt, &q.error);
  return q;
}

/// mj_forward on the model at the bodies' poses; every contact, converted (with `margin`, those
/// within the geoms' margin too, at negative depth).
ContactResult query_model(QueryModel& q, const RigidBody& a, const RigidBody& b,
                          bool margin = false) {
  if (!q.m) return {Status::Error, q.error, {}};
  ContactResult r;
  set_state(q.m.get(), q.d.get(), {a, b});
  const mjModel* mc = q.m.get();
  mjData* dd = q.d.get();
  t_trap.clear_warning();
  if (!guarded([&] { mj_forward(mc, dd); }))
    return {Status::Error, std::string("MuJoCo mj_forward: ") + t_trap.error, {}};
  if (t_trap.has_warning())
    return {Status::Error, std::string("MuJoCo warning: ") + t_trap.warning, {}};
  const int body_a = mc->geom_bodyid[geom_of(mc, 0)];
  for (int i = 0; i < dd->ncon; ++i) {
    const mjContact& c = dd->contact[i];
    if (c.dist > 0.0 && !margin) continue;  // within a margin only (contact queries have none)
    r.contacts.push_back(convert_contact(c, mc->geom_bodyid[c.geom1] == body_a));
    r.contacts.back().feature = q.opt.box_geoms ? "box-box" : "mesh";
  }
  // 2.2.2's box-box collider reports half the depth (pinned in tests/reference/mujoco_test.cpp):
  // passed on, labelled.
  if (q.opt.box_geoms && !r.contacts.empty())
    r.message = "MuJoCo 2.2.2 box-box: depth reported at half its true value (known defect)";
  return r;
}

/// 2.2.2 has no distance query: the nearest contact within a margin just past the centres'
/// distance (they lie inside the bodies, so one is always found) answers (docs/distance.md).
DistanceResult distance_of(const RigidBody& a, const RigidBody& b, const MujocoSettings& settings) {
  QueryModel q = make_query_model(a, b, settings, 1.01 * (a.position - b.position).norm() + 1e-9);
  const ContactResult c = query_model(q, a, b, /*margin=*/true);
  DistanceResult r;
  r.status = c.status;
  r.message = c.status == Status::Ok ? "" : c.message;  // not its contacts' depth label
  const ContactPoint* nearest = nullptr;
  for (const ContactPoint& p : c.contacts)
    if (!nearest || p.depth > nearest->depth) nearest = &p;
  if (c.status == Status::Ok && !nearest) {
    r.status = Status::Error;
    r.message = "MuJoCo reported no contact within a margin past the pair's centres";
  }
  if (r.status != Status::Ok) return r;
  r.overlapping = nearest->depth > 0;
  if (r.overlapping) return r;
  // The normal points from B toward A; the position is the midpoint.
  r.distance = -nearest->depth;
  r.point_a = nearest->point + 0.5 * r.distance * nearest->normal;
  r.point_b = nearest->point - 0.5 * r.distance * nearest->normal;
  r.message = "a contact within the margin: its distance along the collider's normal";
  return r;
}

/// The contact query with the pair's model compiled once per thread (variant "prebuilt").
ContactResult prebuilt_query(const RigidBody& a, const RigidBody& b, const MujocoSettings& settings,
                             PrebuiltCache<QueryModel>& cache) {
  QueryModel& q = cache.get(a.shape, b.shape, [&] { return make_query_model(a, b, settings); });
  return query_model(q, a, b);
}

}  // namespace

namespace {

ContactResult mujoco_contact_with(const RigidBody& a, const RigidBody& b,
                                  const MujocoSettings& settings) {
  QueryModel q = make_query_model(a, b, settings);
  return query_model(q, a, b);
}

}  // namespace

namespace {

// The model options of a scene run at time step dt. Restitution goes through the soft
// contact's damping (MuJoCo has no coefficient of restitution); `note` says when the scene's
// restitution is below what the soft contact can reach.
ModelOptions model_options(const WorldDefinition& scene, double dt,
                           const std::vector<RigidBody>& bodies, const MujocoSettings& settings,
                           std::string& note) {
  ModelOptions mo;
  mo.dt = dt;
  mo.gravity = scene.sim.gravity;
  const double zeta = restitution_damping_ratio(scene.sim.restitution, settings.contact_steps);
  mo.contact.stiffness = contact_stiffness(dt, settings.contact_steps);
  mo.contact.damping = 2.0 * zeta * std::sqrt(mo.contact.stiffness);
  mo.contact.friction = scene.sim.friction;
  mo.contact.impedance = settings.impedance;
  mo.box_geoms = use_box_geoms(bodies, settings);
  mo.multiccd = settings.multiccd;
  mo.elliptic_cone = settings.elliptic_cone;
  mo.impratio = settings.impratio;
  mo.noslip_iterations = settings.noslip_iterations;
  // Box-box depth is reported halved (see the file comment): the stiffness makes up for it, so
  // that the contact force per true penetration is the mesh's.
  if (mo.box_geoms) mo.contact.stiffness *= settings.box_stiffness_factor;
  if (const double reached = soft_contact_restitution(zeta, 0.5, settings.contact_steps);
      reached > scene.sim.restitution + 1e-9)
    note = "restitution " + num(scene.sim.restitution) +
           " below what the soft contact can reach; used " + num(reached);
  return mo;
}

// Collision events: one per contact episode of a pair (the soft impact spans several steps),
// at its first step with a pushing force; the impulse sums force * dt over the episode.
struct Episodes {
  using Pair = std::pair<int, int>;
  std::map<Pair, size_t> open;     // pair -> its episode's index in the run's events
  std::map<Pair, int> points;      // pushing contacts per pair in the last step
  std::map<Pair, double> deepest;  // m, per pair in the last step

  // Reads the contacts of step `step` (d->contact and efc_force describe the state at its
  // start) into `events`: new episodes appended, open ones given this step's impulse.
  void read_step(const mjModel* mc, mjData* dd, const std::vector<int>& scene_of_geom,
                 const std::vector<RigidBody>& bodies, bool box_geoms, long step, double dt,
                 std::vector<CollisionEvent>& events);
  // The pair whose episode is event `index`, or (-1, -1).
  Pair pair_of(size_t index) const {
    Pair key{-1, -1};
    for (const auto& [k, idx] : open)
      if (idx == index) key = k;
    return key;
  }
};

void Episodes::read_step(const mjModel* mc, mjData* dd, const std::vector<int>& scene_of_geom,
                         const std::vector<RigidBody>& bodies, bool box_geoms, long step, double dt,
                         std::vector<CollisionEvent>& events) {
  std::map<Pair, size_t> still_open;
  points.clear();
  deepest.clear();
  for (int c = 0; c < dd->ncon; ++c) {
    const mjContact& con = dd->contact[c];
    if (con.efc_address < 0) continue;
    mjtNum frame_force[6];  // contact frame: [0] is the normal force (N)
    mj_contactForce(mc, dd, c, frame_force);
    const double force = frame_force[0];
    if (!(force > 0.0)) continue;
    const int g1 = scene_of_geom[con.geom1], g2 = scene_of_geom[con.geom2];
    const int ia = std::min(g1, g2), ib = std::max(g1, g2);
    const Pair key{ia, ib};
    // The pair's episode: opened by another of its contact points this step (a multi-point
    // manifold is one episode, not one per point), open since an earlier step, or new.
    size_t idx;
    if (auto in_step = still_open.find(key); in_step != still_open.end()) {
      idx = in_step->second;
    } else if (auto earlier = open.find(key); earlier != open.end()) {
      idx = earlier->second;
    } else {
      CollisionEvent ev;
      ev.time = step * dt;
      ev.step = step;
      ev.body_a = bodies[ia].name;
      ev.body_b = bodies[ib].name;
      ev.contact = convert_contact(con, g1 == ia);
      ev.contact.feature = box_geoms ? "box-box" : "mesh";
      events.push_back(ev);
      idx = events.size() - 1;
    }
    events[idx].impulse += force * dt;
    still_open[key] = idx;
    ++points[key];
    deepest[key] = std::max(deepest[key], -con.dist);
  }
  open = std::move(still_open);
}

// Every contact of step `step` in the constraint solve, with the impulse on its body A over the
// step (the force mj_contactForce gives in the contact frame, in world axes, times dt), given to
// `recorder`. The force acts on geom2 along the frame (its normal points from geom1 to geom2),
// so on geom1 against it.
void record_contacts(const mjModel* mc, mjData* dd, const std::vector<int>& scene_of_geom,
                     double dt, DynamicsRecorder& recorder) {
  for (int i = 0; i < dd->ncon; ++i) {
    const mjContact& con = dd->contact[i];
    if (con.efc_address < 0) continue;
    mjtNum frame_force[6];
    mj_contactForce(mc, dd, i, frame_force);
    Vec3 on_geom2 = Vec3::Zero();
    for (int r = 0; r < 3; ++r)
      on_geom2 +=
          frame_force[r] * Vec3(con.frame[3 * r], con.frame[3 * r + 1], con.frame[3 * r + 2]);
    const int g1 = scene_of_geom[con.geom1], g2 = scene_of_geom[con.geom2];
    const ContactPoint cp = convert_contact(con, g1 < g2);
    SolvedContact c;
    c.a = std::min(g1, g2);
    c.b = std::max(g1, g2);
    c.point = cp.point;
    c.normal = cp.normal;
    c.depth = std::max(0.0, cp.depth);
    c.impulse = (g1 < g2 ? Vec3(-on_geom2) : on_geom2) * dt;
    recorder.contact_at_start(c);
  }
}

}  // namespace

namespace {

DynamicsResult mujoco_dynamics_with(const WorldDefinition& scene, const DynamicsOptions& opt,
                                    const MujocoSettings& settings) {
  DynamicsResult r;
  const double dt = opt.dt > 0.0 ? opt.dt : scene.sim.dt;
  if (!(dt > 0.0)) return {Status::Error, "MuJoCo: time step must be > 0", {}, {}, {}, {}, {}};
  const long steps = step_count(scene.sim.duration, dt);  // throws when uncountable
  const std::vector<RigidBody> bodies = make_bodies(scene);

  const ModelOptions mo = model_options(scene, dt, bodies, settings, r.message);
  std::string error;
  auto [m, d] = make_simulation(bodies, /*all_free=*/false, mo, &error);
  if (!m) {
    r.status = Status::Error;
    r.message = error;
    return r;
  }
  if (opt.budget > 0) m->opt.iterations = opt.budget;  // the studied budget (mujoco_budget)
  const mjModel* mc = m.get();
  mjData* dd = d.get();
  set_state(mc, dd, bodies);

  // Scene index of each geom's owner, and of each MuJoCo body.
  std::vector<int> scene_of_geom(mc->ngeom, -1);
  for (size_t i = 0; i < bodies.size(); ++i) scene_of_geom[geom_of(mc, i)] = static_cast<int>(i);

  DynamicsRecorder recorder(r, opt, [&] {
    std::vector<BodyFinal> states;
    for (size_t i = 0; i < bodies.size(); ++i) states.push_back(read_state(mc, dd, bodies[i], i));
    return states;
  });
  Episodes episodes;
  t_trap.clear_warning();
  recorder.measure_contact_laws(scene);
  recorder.start();
  for (long step = 0; step < steps; ++step) {
    recorder.before_step(r.events);
    if (!guarded([&] { mj_step(mc, dd); })) {
      r.status = Status::Error;
      r.message = "MuJoCo mj_step at step " + std::to_string(step) + ": " + t_trap.error;
      return r;
    }
    if (t_trap.has_warning()) {
      r.status = Status::Error;
      r.message = "MuJoCo warning at step " + std::to_string(step) + ": " + t_trap.warning;
      return r;
    }
    episodes.read_step(mc, dd, scene_of_geom, bodies, mo.box_geoms, step, dt, r.events);
    // The first impulse: the episode's event holds one contact; count and depth are the step's.
    if (const CollisionEvent* first = recorder.first_new_event(r.events)) {
      const Episodes::Pair key = episodes.pair_of(static_cast<size_t>(first - r.events.data()));
      recorder.first_impulse_from_event(*first, dt, episodes.points[key]);
      r.first_impulse.depth = episodes.deepest[key];
    }
    record_contacts(mc, dd, scene_of_geom, dt, recorder);
    recorder.after_step(step + 1, (step + 1) * dt);
  }

  recorder.finish("MuJoCo");
  return r;
}

}  // namespace

namespace {

// `mujoco`: contacts from mj_forward on box geoms for two boxes, mesh geoms with multiccd
// otherwise (boxes among hulls too).
ContactResult mujoco_contact(const RigidBody& a, const RigidBody& b) {
  // Two boxes meet in MuJoCo's own box-box collider, as in its dynamics and as its own tests
  // exercise it (its normals there are right where the meshes' MPR is not); 2.2.2 reports half
  // the depth there, passed on and labelled (query_model). `mujoco-hull` keeps the meshes.
  return mujoco_contact_with(a, b, mujoco_query_settings());
}

// `mujoco-hull`: contacts of mesh geoms from mj_forward (MPR, one point).
ContactResult mujoco_hull_contact(const RigidBody& a, const RigidBody& b) {
  return mujoco_contact_with(a, b, mujoco_hull_settings());
}

// `mujoco`: mj_step with e mapped to solref, native geoms.
DynamicsResult mujoco_dynamics(const WorldDefinition& scene, const DynamicsOptions& opt) {
  return mujoco_dynamics_with(scene, opt, MujocoSettings{});
}

// `mujoco-hull`: the same on mesh geoms.
DynamicsResult mujoco_hull_dynamics(const WorldDefinition& scene, const DynamicsOptions& opt) {
  return mujoco_dynamics_with(scene, opt, mujoco_hull_settings());
}

// `mujoco` and `mujoco-hull` with the pair's model compiled once and kept (reference/
// prebuilt_cache.h), each query setting the poses and running mj_forward: variant "prebuilt".
ContactResult mujoco_contact_prebuilt(const RigidBody& a, const RigidBody& b) {
  thread_local PrebuiltCache<QueryModel> cache;
  return prebuilt_query(a, b, mujoco_query_settings(), cache);
}

ContactResult mujoco_hull_contact_prebuilt(const RigidBody& a, const RigidBody& b) {
  thread_local PrebuiltCache<QueryModel> cache;
  return prebuilt_query(a, b, mujoco_hull_settings(), cache);
}

MassResult mujoco_hull_mass(const RigidBody& body);

// `mujoco` mass: MuJoCo's own inertia of a box geom for a box body (inertiafromgeom), of the
// hull mesh otherwise.
MassResult mujoco_mass(const RigidBody& body) {
  return is_native_box(body) ? mass_of_geom(body, true) : mujoco_hull_mass(body);
}

// `mujoco-hull` mass: a free body with one mesh geom of the body's mass, compiled with
// inertiafromgeom; body_mass, body_ipos and body_inertia/body_iquat read back.
MassResult mujoco_hull_mass(const RigidBody& body) { return mass_of_geom(body, false); }

}  // namespace

const AtSettings<MujocoSettings>& mujoco_at_settings() {
  static const AtSettings<MujocoSettings> entries = {mujoco_contact_with, mujoco_dynamics_with};
  return entries;
}

// The budget studied: the constraint solver's iterations (Newton, MuJoCo's default solver;
// it stops earlier at its tolerance, 1e-8), library default 100, which rbx keeps.
SolverBudget mujoco_budget() {
  return {"opt.iterations (Newton solver)", {1, 3, 10, 100}, 100, 100};
}

// The contact softness MuJoCo's users tune, from `base`'s settings: solref's time constant (the
// undamped contact's duration in steps; a fit tries from 5, MuJoCo's documented floor for it
// being 2 dt, to 60 steps) and solimp's impedance (constant; 0.5 to 0.999, MuJoCo's default dmin
// being 0.9).
SoftContact mujoco_soft(const MujocoSettings& base) {
  return {{{"contact_steps",
            "undamped soft-contact duration in steps (solref's time constant over dt; the damping "
            "follows from e)",
            base.contact_steps,
            3.0,
            1000.0,
            {5, 10, 15, 25, 40, 60}},
           {"impedance",
            "solimp's constant impedance d (dmin = dmax): the share of the contact's reference "
            "acceleration the solver enforces (MuJoCo's range 1e-4 to 0.9999)",
            base.impedance,
            1e-4,
            0.9999,
            {0.5, 0.7, 0.8, 0.9, 0.95, 0.99, 0.999}}},
          [base](const WorldDefinition& scene, const DynamicsOptions& opt,
                 const std::vector<double>& v) {
            MujocoSettings s = base;
            s.contact_steps = v.at(0);
            s.impedance = v.at(1);
            return mujoco_dynamics_with(scene, opt, s);
          }};
}

const Adapter& mujoco_adapter() {
  static const Adapter adapter = {
      {
          with_soft(with_budget({"mujoco",
                                 "MuJoCo 2.2.2 box geoms (box-box) or mesh + multiccd; mj_step, "
                                 "negative solref",
                                 mujoco_contact, mujoco_dynamics, mujoco_mass},
                                mujoco_budget()),
                    mujoco_soft(MujocoSettings{}))
              .measuring([](const RigidBody& a, const RigidBody& b) {
                return distance_of(a, b, MujocoSettings{});
              })
              .drawn("#D55E00", "o")
              .timed(8192, 512),
          with_soft(with_budget({"mujoco-hull",
                                 "MuJoCo 2.2.2 mesh geoms (MPR, one point); mj_step, negative "
                                 "solref",
                                 mujoco_hull_contact, mujoco_hull_dynamics, mujoco_hull_mass},
                                mujoco_budget()),
                    mujoco_soft(mujoco_hull_settings()))
              .measuring([](const RigidBody& a, const RigidBody& b) {
                return distance_of(a, b, mujoco_hull_settings());
              })
              .drawn("#7A2E00", "s"),
      },
      {
          {"mujoco", "prebuilt", "the pair's model compiled once and kept (poses set, mj_forward)",
           mujoco_contact_prebuilt},
          {"mujoco-hull", "prebuilt", "the pair's model compiled once and kept",
           mujoco_hull_contact_prebuilt},
      }};
  return adapter;
}

}  // namespace rbx
