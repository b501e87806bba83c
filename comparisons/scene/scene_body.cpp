// A [[body]] table of a scene file to a BodySpec: its name, its shape (box, icosphere, prism,
// convex points or an OBJ mesh), its mass and its pose, each value checked where it is read.
#include <cmath>
#include <memory>

#include "comparisons/scene/mesh_io.h"
#include "comparisons/scene/scene_reader.h"
#include "engine/format.h"

namespace rbx::scene_detail {

namespace {

namespace fs = std::filesystem;

// The fastest a body or a point of it may move (m/s): the speed of light. Rigid bodies and
// Newton's impacts are the model up to there; the custom engine's time of impact is certified
// up to there or stops the run saying it is not (engine/time_of_impact.h).
constexpr double kMaxSpeed = 299792458.0;

// Name first: every other message names the body by it.
std::string read_body_name(const Reader& r, const toml::table& t) {
  const toml::node* name_node = t.get("name");
  if (!name_node)
    r.fail(line_of(&t), "body.name", "this [[body]] has no name",
           "add name = \"...\" (unique within the scene)");
  const std::string name = r.string(*name_node, "body.name", "body.name");
  if (name.empty())
    r.fail(line_of(name_node), "body.name", "the name is empty", "give the body a unique name");
  return name;
}

// Keys that belong to another shape than the body's.
void check_shape_keys(const Reader& r, const toml::table& t, const std::string& p, ShapeKind kind) {
  for (const auto& [key, node] : in_file_order(t)) {
    std::vector<std::string> owners;  // shapes that take this key (none: any shape)
    for (const auto& [k, shape] : kShapeKeys)
      if (k == key) owners.push_back(shape);
    if (!owners.empty() && std::find(owners.begin(), owners.end(), to_string(kind)) == owners.end())
      r.fail(key_line(t, key), p + key,
             "only valid for shape = \"" + join_quoted(owners) + "\", but this body's shape is \"" +
                 to_string(kind) + "\"",
             "remove it, or set shape = \"" + owners.front() + "\"");
  }
}

// A length of a shape (radius, height), `fallback` when absent.
double positive_length(const Reader& r, const toml::table& t, const std::string& p, const char* key,
                       double fallback, const char* what) {
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
}

ConvexPolyhedron read_box(const Reader& r, const toml::table& t, const std::string& p,
                          BodySpec& b) {
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
  return make_box(b.box_size);
}

// A count of a shape (subdivisions, sides) in [lo, hi], `fallback` when absent; `fix` says
// what to write instead.
int bounded_count(const Reader& r, const toml::table& t, const std::string& p, const char* key,
                  long fallback, long lo, long hi, const std::string& fix) {
  const toml::node* n = t.get(key);
  if (!n) return static_cast<int>(fallback);
  const long v = r.integer(*n, p + key, std::string("body.") + key);
  if (v < lo || v > hi)
    r.fail(line_of(n), p + key,
           "must be in " + std::to_string(lo) + ".." + std::to_string(hi) + ", got " +
               std::to_string(v),
           fix);
  return static_cast<int>(v);
}

// Defaults: radius 0.5 with 2 subdivisions.
ConvexPolyhedron read_icosphere(const Reader& r, const toml::table& t, const std::string& p) {
  const double radius = positive_length(r, t, p, "radius", 0.5, "radius");
  return make_icosphere(
      radius,
      bounded_count(r, t, p, "subdivisions", 2, 0, 6,
                    "6 already gives 81920 triangles, and 2 (320 triangles) is the default"));
}

// Defaults: radius 0.5, height 1, 6 sides.
ConvexPolyhedron read_prism(const Reader& r, const toml::table& t, const std::string& p) {
  const double radius = positive_length(r, t, p, "radius", 0.5, "radius");
  const double height = positive_length(r, t, p, "height", 1.0, "height");
  return make_prism(radius, height,
                    bounded_count(r, t, p, "sides", 6, 3, 100000,
                                  "use 3 (a triangular prism) or more, up to 100000"));
}

ConvexPolyhedron read_convex(const Reader& r, const toml::table& t, const std::string& p) {
  const toml::node* n = t.get("vertices");
  if (!n)
    r.fail(line_of(&t), p + "vertices", "missing for shape = \"convex\"",
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
    return convex_hull(points);
  } catch (const GeometryError& e) {
    r.fail(line_of(n), p + "vertices", e.what(),
           "give at least 4 points that are not all in one plane");
  }
}

// An OBJ file, relative to the scene's folder; `hull = true` takes its convex hull.
ConvexPolyhedron read_mesh(const Reader& r, const toml::table& t, const std::string& p,
                           const fs::path& folder) {
  const toml::node* n = t.get("file");
  if (!n)
    r.fail(line_of(&t), p + "file", "missing for shape = \"mesh\"",
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
    return load_obj(resolved.string(), hull);
  } catch (const ObjReadError& e) {
    // Not readable as OBJ text: the error says what would help (hull = true would not).
    r.fail(line_of(n), p + "file", e.what(), e.fix());
  } catch (const GeometryError& e) {
    std::string what = e.what();
    const std::string hint = " (use hull = true for its convex hull)";
    if (const size_t at = what.find(hint); at != std::string::npos) what.erase(at, hint.size());
    r.fail(line_of(n), p + "file", what,
           hull ? "fix the OBJ file: its vertices must span a volume"
                : "fix the OBJ file, or set hull = true to use the convex hull of its vertices");
  }
}

// The body's shape, by its kind.
std::shared_ptr<const ConvexPolyhedron> read_shape(const Reader& r, const toml::table& t,
                                                   const std::string& p, const fs::path& folder,
                                                   BodySpec& b) {
  try {
    switch (b.shape_kind) {
      case ShapeKind::Box:
        return std::make_shared<const ConvexPolyhedron>(read_box(r, t, p, b));
      case ShapeKind::Icosphere:
        return std::make_shared<const ConvexPolyhedron>(read_icosphere(r, t, p));
      case ShapeKind::Prism:
        return std::make_shared<const ConvexPolyhedron>(read_prism(r, t, p));
      case ShapeKind::Convex:
        return std::make_shared<const ConvexPolyhedron>(read_convex(r, t, p));
      default:
        return std::make_shared<const ConvexPolyhedron>(read_mesh(r, t, p, folder));
    }
  } catch (const GeometryError& e) {
    // The engine's own checks, should a value pass ours.
    r.fail(t.get("shape") ? line_of(t.get("shape")) : line_of(&t), p + "shape", e.what(),
           "fix the shape's parameters");
  }
}

// Mass, static and mass model.
void read_mass(const Reader& r, const toml::table& t, const std::string& p, BodySpec& b) {
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
}

// A unit quaternion [w, x, y, z], within kUnitQuaternionTolerance (renormalised, and said so
// where it is more than round-off).
Quat read_quaternion(const Reader& r, const toml::node& n, const std::string& p,
                     std::vector<std::string>& notes) {
  const std::vector<double> q =
      r.numbers(n, p + "orientation", "body.orientation", {"w", "x", "y", "z"});
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(std::abs(norm - 1.0) <= kUnitQuaternionTolerance))
    r.fail(line_of(&n), p + "orientation",
           "quaternion [w, x, y, z] has norm " + fixed10(norm) + ", must be 1 within 1e-6",
           "write its components to at least 7 significant digits, or use rotation (degrees)");
  if (std::abs(norm - 1.0) > 1e-12)
    notes.push_back(p + "orientation: norm " + fixed10(norm) + " normalised to 1");
  return Quat(q[0], q[1], q[2], q[3]).normalized();
}

// Pose and velocities: rotation (degrees, R = Rz Ry Rx) or a unit quaternion, not both.
void read_pose(const Reader& r, const toml::table& t, const std::string& p, BodySpec& b,
               std::vector<std::string>& notes) {
  if (const toml::node* n = t.get("position")) {
    b.position = r.vec3(*n, p + "position", "body.position");
    // Beyond kMaxLength, squared lengths overflow, as for a shape's coordinates.
    if (!(b.position.cwiseAbs().maxCoeff() <= kMaxLength))
      r.fail(line_of(n), p + "position",
             "coordinates must be within 1e12 m of the origin, got " + vec_text(b.position),
             "give it in metres");
  }
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
  if (orientation) b.orientation = read_quaternion(r, *orientation, p, notes);
  if (const toml::node* n = t.get("velocity")) {
    b.velocity = r.vec3(*n, p + "velocity", "body.velocity");
    if (!(b.velocity.norm() <= kMaxSpeed))
      r.fail(line_of(n), p + "velocity",
             "speed " + num(b.velocity.norm()) + " m/s is above the speed of light (" +
                 num(kMaxSpeed) + " m/s), where rigid-body mechanics does not hold",
             "give it in m/s, at most 2.99792458e8");
  }
  if (const toml::node* n = t.get("angular_velocity")) {
    b.angular_velocity = r.vec3(*n, p + "angular_velocity", "body.angular_velocity");
    // The speed of the vertex farthest from the body's origin, by the same limit.
    double radius = 0.0;
    for (const Vec3& v : b.shape->vertices()) radius = std::max(radius, v.norm());
    if (!(b.angular_velocity.norm() * radius <= kMaxSpeed)) {
      // The largest rate, rounded down to 4 digits so that the suggestion is accepted.
      const double most = kMaxSpeed / radius;
      const double unit = std::pow(10.0, std::floor(std::log10(most)) - 3);
      r.fail(line_of(n), p + "angular_velocity",
             "spins its farthest vertex (" + fmt_num(radius) + " m out) at " +
                 fmt_num(b.angular_velocity.norm() * radius) + " m/s, above the speed of light (" +
                 num(kMaxSpeed) + " m/s)",
             "give it in rad/s, at most " + fmt_num(std::floor(most / unit) * unit) +
                 " for this body");
    }
  }
}

}  // namespace

BodySpec read_body(const Reader& r, const toml::table& t, const fs::path& folder,
                   std::vector<std::string>& notes) {
  BodySpec b;
  b.name = read_body_name(r, t);
  const std::string p = "body." + b.name + ".";
  r.check_keys(t, p, keys_under("body."), false);
  if (const toml::node* n = t.get("shape"))
    b.shape_kind =
        *shape_kind_from_string(one_of(r, *n, p + "shape", "body.shape", kShapes, "shape"));
  check_shape_keys(r, t, p, b.shape_kind);
  b.shape = read_shape(r, t, p, folder, b);
  read_mass(r, t, p, b);
  read_pose(r, t, p, b, notes);
  return b;
}

}  // namespace rbx::scene_detail
