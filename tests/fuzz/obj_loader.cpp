// Fuzz target `obj_loader`: rbx::load_obj on the bytes as a file, and
// ConvexPolyhedron::from_triangles on the bytes decoded as arrays (see targets.h).
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "comparisons/scene/mesh_io.h"
#include "tests/fuzz/byte_reader.h"
#include "tests/fuzz/targets.h"

namespace rbx::fuzz {

namespace {

namespace fs = std::filesystem;

// One scratch OBJ file per process, rewritten for every input, removed at exit.
class ScratchFile {
 public:
  ScratchFile()
      : path_((fs::temp_directory_path() / ("rbx_fuzz_" + std::to_string(getpid()) + ".obj"))
                  .string()) {}
  ~ScratchFile() {
    std::error_code ec;
    fs::remove(path_, ec);
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  /// Replaces the file's content with the bytes.
  const std::string& write(const uint8_t* data, size_t size) const {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    return path_;
  }

 private:
  std::string path_;
};

// What ConvexPolyhedron promises of every polyhedron it builds (engine/polyhedron.h: closed,
// consistently oriented outward, convex, positive volume, unit outward planes).
void check_polyhedron(const ConvexPolyhedron& p, const std::string& origin) {
  const auto& v = p.vertices();
  const auto& t = p.triangles();
  require(v.size() >= 4 && t.size() >= 4, origin + ": fewer than 4 vertices or faces");
  for (const Vec3& x : v) require(x.allFinite(), origin + ": non-finite vertex");
  require(std::isfinite(p.volume()) && p.volume() > 0, origin + ": volume not positive");
  // Closed and consistently oriented: every directed edge once, and its reverse once.
  std::map<std::pair<int, int>, int> directed;
  for (const auto& f : t)
    for (int k = 0; k < 3; ++k) ++directed[{f[k], f[(k + 1) % 3]}];
  for (const auto& [e, count] : directed) {
    require(count == 1, origin + ": a directed edge is used twice");
    require(directed.count({e.second, e.first}) == 1, origin + ": open edge");
  }
  require(p.edges().size() * 2 == directed.size(), origin + ": edge list disagrees with faces");
  // Convex: every vertex behind every plane. The validator's own tolerance is 1e-9 of the size;
  // 1e-8 here leaves a factor 10 for the round-off of recomputing the distances.
  const Aabb& box = p.bounds();
  const double size = std::max((box.max - box.min).maxCoeff(), box.max.cwiseAbs().maxCoeff());
  const double scale = std::max(size, box.min.cwiseAbs().maxCoeff());
  require(p.planes().size() == t.size(), origin + ": one plane per triangle");
  for (const Plane& plane : p.planes()) {
    require(std::abs(plane.normal.norm() - 1.0) < 1e-12, origin + ": plane normal not unit");
    for (const Vec3& x : v) require(plane.distance(x) <= 1e-8 * scale, origin + ": not convex");
  }
}

// Decodes vertex and triangle arrays: a count byte, then per coordinate one signed byte on a
// 1/8 m grid (escape -128: a raw 8-byte double, so NaN, infinities and extremes occur), then a
// triangle count and three signed-byte indices per triangle (negative and out-of-range indices
// occur on purpose).
void decode_mesh(ByteReader& in, std::vector<Vec3>& vertices,
                 std::vector<std::array<int, 3>>& triangles) {
  const int nv = in.u8() % 33;
  for (int i = 0; i < nv; ++i)
    vertices.emplace_back(in.coordinate(), in.coordinate(), in.coordinate());
  const int nt = in.u8() % 65;
  for (int f = 0; f < nt; ++f) triangles.push_back({in.i8(), in.i8(), in.i8()});
}

}  // namespace

void obj_loader(const uint8_t* data, size_t size) {
  static const ScratchFile scratch;
  const std::string& path = scratch.write(data, size);
  for (const bool hull : {false, true}) {
    const std::string origin = std::string("load_obj(hull = ") + (hull ? "true" : "false") + ")";
    try {
      check_polyhedron(load_obj(path, hull), origin);
    } catch (const GeometryError& e) {
      const std::string message = e.what();
      require(message.find('\n') == std::string::npos,
              origin + ": message spans lines: " + message);
      require(message.rfind(path, 0) == 0,
              origin + ": message does not start with the path: " + message);
    }
  }

  // The same bytes as arrays, straight into the validator.
  ByteReader in(data, size);
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
  decode_mesh(in, vertices, triangles);
  try {
    check_polyhedron(ConvexPolyhedron::from_triangles(vertices, triangles), "from_triangles");
  } catch (const GeometryError& e) {
    require(std::strchr(e.what(), '\n') == nullptr, "from_triangles: message spans lines");
  }
}

}  // namespace rbx::fuzz
