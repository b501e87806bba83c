// Meshes from outside: convex hulls with Qhull (reentrant C API) and OBJ files with
// tinyobjloader (double build). Both end in ConvexPolyhedron::from_triangles, the one validator.
#include "comparisons/scene/mesh_io.h"

#include <tiny_obj_loader.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

namespace rbx {

namespace {

// Replaces line breaks so that a message stays one line.
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// First line of a multi-line library message, trimmed.
std::string first_line(const std::string& s) {
  std::string line = s.substr(0, s.find('\n'));
  while (!line.empty() && (line.back() == ' ' || line.back() == '\r' || line.back() == '.'))
    line.pop_back();
  return line;
}

// Collects everything Qhull writes to its error stream into a string (POSIX open_memstream),
// so that its diagnosis can go into the GeometryError instead of stderr.
class CapturedStream {
 public:
  CapturedStream() { file_ = open_memstream(&buffer_, &size_); }
  ~CapturedStream() {
    if (file_) std::fclose(file_);
    std::free(buffer_);
  }
  CapturedStream(const CapturedStream&) = delete;
  CapturedStream& operator=(const CapturedStream&) = delete;
  FILE* file() const { return file_ ? file_ : stderr; }
  std::string text() {
    if (!file_) return "";
    std::fflush(file_);
    return buffer_ ? std::string(buffer_, size_) : std::string();
  }

 private:
  FILE* file_ = nullptr;
  char* buffer_ = nullptr;
  size_t size_ = 0;
};

// The Qhull error code, e.g. "QH6154", and the sentence after it, from its error text.
std::string qhull_diagnosis(const std::string& text) {
  const size_t at = text.find("QH");
  if (at == std::string::npos) return first_line(text);
  return first_line(text.substr(at));
}

}  // namespace

ConvexPolyhedron convex_hull(const std::vector<Vec3>& points) {
  if (points.size() < 4)
    throw GeometryError("a convex hull needs at least 4 points, got " +
                        std::to_string(points.size()));
  for (size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw GeometryError("point " + std::to_string(i) + " is not finite");

  // Input without volume, said in words (Qhull's own message is about its initial simplex):
  // the extent along a line, off that line, and off the plane, each against 1e-10 of the size.
  // That is far above double round-off (1e-16) and far below any meaningful thickness.
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double eps =
      1e-10 * std::max((hi - lo).norm(), hi.cwiseAbs().cwiseMax(lo.cwiseAbs()).maxCoeff());
  const std::string count = "the " + std::to_string(points.size()) + " points";
  auto farthest = [&](auto distance) {
    size_t best = 0;
    for (size_t i = 1; i < points.size(); ++i)
      if (distance(points[i]) > distance(points[best])) best = i;
    return std::make_pair(best, distance(points[best]));
  };
  const Vec3 p0 = points[0];
  const auto [i1, d1] = farthest([&](const Vec3& p) { return (p - p0).norm(); });
  if (!(d1 > eps)) throw GeometryError(count + " all coincide, so their hull has no volume");
  const Vec3 u = (points[i1] - p0) / d1;
  auto off_line = [&](const Vec3& p) { return ((p - p0) - (p - p0).dot(u) * u).norm(); };
  const auto [i2, d2] = farthest(off_line);
  if (!(d2 > eps)) throw GeometryError(count + " all lie on one line, so their hull has no volume");
  const Vec3 n = u.cross(points[i2] - p0).normalized();
  const auto [i3, d3] = farthest([&](const Vec3& p) { return std::abs((p - p0).dot(n)); });
  (void)i3;
  if (!(d3 > eps))
    throw GeometryError(count + " all lie in one plane, so their hull has no volume");

  // Qhull wants a flat, mutable coordinate array.
  std::vector<coordT> coords;
  coords.reserve(3 * points.size());
  for (const Vec3& p : points) coords.insert(coords.end(), {p.x(), p.y(), p.z()});

  // "Qt": triangulated output, so every facet is a triangle. Default precision handling merges
  // coplanar facets first, so points inside a face or on an edge do not become vertices.
  CapturedStream errors;
  qhT qh_storage;
  qhT* qh = &qh_storage;
  QHULL_LIB_CHECK
  qh_zero(qh, errors.file());
  char flags[] = "qhull Qt";
  const int exitcode = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords.data(), False,
                                    flags, nullptr, errors.file());

  // Read the facets, mapping Qhull point ids to a compact vertex list (interior and coplanar
  // points are dropped: ConvexPolyhedron refuses unused vertices).
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
  std::map<int, int> compact;  // Qhull point id -> our vertex index
  if (exitcode == 0) {
    facetT* facet;
    vertexT *vertex, **vertexp;
    FORALLfacets {
      std::array<int, 3> tri{};
      int k = 0;
      FOREACHvertex_(facet->vertices) {
        if (k < 3) {
          const int id = qh_pointid(qh, vertex->point);
          auto it = compact.find(id);
          if (it == compact.end()) {
            it = compact.emplace(id, static_cast<int>(vertices.size())).first;
            vertices.push_back(points[id]);
          }
          tri[k] = it->second;
        }
        ++k;
      }
      if (k != 3) continue;  // cannot happen with Qt in 3-d; guarded for safety
      // Qhull's vertex order carries no orientation by itself (that is facet->toporient);
      // comparing with the outward facet normal is the same decision without the parity rule.
      const Vec3 n(facet->normal[0], facet->normal[1], facet->normal[2]);
      const Vec3 a = vertices[tri[0]], b = vertices[tri[1]], c = vertices[tri[2]];
      if ((b - a).cross(c - a).dot(n) < 0) std::swap(tri[1], tri[2]);
      triangles.push_back(tri);
    }
  }
  const std::string diagnosis = exitcode ? qhull_diagnosis(errors.text()) : "";

  // Free Qhull's memory before anything can throw.
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);

  if (exitcode != 0) throw GeometryError("Qhull could not build the hull: " + one_line(diagnosis));
  return ConvexPolyhedron::from_triangles(std::move(vertices), std::move(triangles));
}

namespace {

// File line numbers of the OBJ's vertex ('v') and face ('f') statements, in file order, so
// that messages can point at lines. Faces with fewer than 3 corners are reported here, since
// tinyobjloader drops them with only a warning.
struct ObjLines {
  std::vector<int> vertex_line;
  std::vector<int> face_line;
};

// What fixes a malformed 'v' line.
constexpr const char* kVertexFix =
    "write each vertex as v x y z, three finite numbers (a fourth, w, must be finite too)";

// A decimal number as OBJ writes one ("-1", "0.5", "2.5e-3"); strtod alone would also take
// "nan", "inf" and hexadecimal, which tinyobjloader does not.
bool decimal_number(const std::string& word) {
  static const std::regex number(R"([+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?)");
  return std::regex_match(word, number);
}

// Checks one 'v' statement strictly (tinyobjloader reads a bad or missing coordinate as 0,
// silently giving another shape): x y z, then at most w, every one a finite decimal number.
// A '#' ends the statement (a trailing comment).
void check_vertex_line(std::istringstream& words, const std::string& path, int number) {
  static const char* const kNames[] = {"x", "y", "z", "w"};
  const std::string where = path + ": line " + std::to_string(number) + ": ";
  int count = 0;
  for (std::string w; words >> w;) {
    if (w[0] == '#') break;
    if (count == 4)
      throw ObjReadError(where + "v line has more than 4 numbers (x y z and an optional w)",
                         kVertexFix);
    const std::string shown = "\"" + (w.size() > 20 ? w.substr(0, 17) + "..." : w) + "\"";
    // "nan", "inf" and overflowing decimals ("1e999") read as numbers, but not finite ones.
    char* end = nullptr;
    const double value = std::strtod(w.c_str(), &end);
    if (*end == '\0' && !std::isfinite(value))
      throw ObjReadError(
          where + "v line: " + kNames[count] + " is " + shown + ", not a finite number",
          kVertexFix);
    if (!decimal_number(w))
      throw ObjReadError(where + "v line: " + kNames[count] + " is " + shown + ", not a number",
                         kVertexFix);
    ++count;
  }
  if (count < 3)
    throw ObjReadError(where + "v line has " + std::to_string(count) +
                           (count == 1 ? " number" : " numbers") + ", a vertex needs 3 (x y z)",
                       kVertexFix);
}

ObjLines scan_obj_lines(const std::string& text, const std::string& path, bool check_faces) {
  ObjLines lines;
  int number = 0;
  // Lines end at "\n", "\r\n" or a lone "\r", as tinyobjloader reads them.
  for (size_t at = 0; at < text.size();) {
    size_t end = text.find_first_of("\r\n", at);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(at, end - at);
    at = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
    ++number;
    std::istringstream words(line);
    std::string tag;
    if (!(words >> tag)) continue;
    if (tag == "v") {
      check_vertex_line(words, path, number);
      lines.vertex_line.push_back(number);
    } else if (tag == "f") {
      int corners = 0;
      for (std::string w; words >> w;) ++corners;
      if (check_faces && corners < 3)
        throw GeometryError(path + ": line " + std::to_string(number) + ": face has " +
                            std::to_string(corners) + " corners, a face needs at least 3");
      lines.face_line.push_back(number);
    }
  }
  return lines;
}

// Adds the OBJ line to every "face N" / "faces N and M" / "vertex N" / "edge A-B" in an engine
// message (the engine counts triangles and vertices from 0 in file order).
std::string annotate(const std::string& message, const ObjLines& lines,
                     const std::vector<int>& triangle_face) {
  auto face_line = [&](int t) {
    if (t < 0 || t >= static_cast<int>(triangle_face.size())) return -1;
    // The scan splits lines as tinyobjloader does; the bound stays as a guard.
    const int f = triangle_face[t];
    return f < static_cast<int>(lines.face_line.size()) ? lines.face_line[f] : -1;
  };
  auto vertex_line = [&](int v) {
    return v >= 0 && v < static_cast<int>(lines.vertex_line.size()) ? lines.vertex_line[v] : -1;
  };
  static const std::regex feature(R"((faces? |vertex |and |edge )(\d+)(?:(-|->)(\d+))?)");
  std::string out;
  std::string last_kind;
  auto begin = std::sregex_iterator(message.begin(), message.end(), feature);
  size_t pos = 0;
  for (auto it = begin; it != std::sregex_iterator(); ++it) {
    const std::smatch& m = *it;
    out += message.substr(pos, m.position() - pos);
    pos = m.position() + m.length();
    std::string kind = m[1].str();
    if (kind == "and ") kind = last_kind;  // "faces 3 and 5": the second is a face too
    last_kind = kind;
    const int a = std::stoi(m[2].str());
    std::string note;
    if (kind == "edge " && m[4].matched) {
      const int b = std::stoi(m[4].str());
      note = " (OBJ lines " + std::to_string(vertex_line(a)) + " and " +
             std::to_string(vertex_line(b)) + ")";
    } else if (kind == "vertex ") {
      note = " (OBJ line " + std::to_string(vertex_line(a)) + ")";
    } else if (kind == "face " || kind == "faces ") {
      note = " (OBJ line " + std::to_string(face_line(a)) + ")";
    }
    out += m.str() + note;
  }
  out += message.substr(pos);
  return out;
}

// The file's text: a readable regular text file, or ObjReadError / GeometryError saying why not.
std::string read_obj_text(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw GeometryError(path + ": file not found");
  if (fs::is_directory(path, ec)) throw GeometryError(path + ": is a folder, not an OBJ file");
  if (!fs::is_regular_file(path, ec))  // /dev/zero, a FIFO: reading would never end
    throw ObjReadError(path + ": is not a regular file (a device or a pipe), not an OBJ file",
                       "name a regular .obj file");
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    // Permissions are the usual cause; anything else (EIO, ...) is named by strerror.
    const int error = errno;
    throw ObjReadError(path + ": cannot be read (" + std::strerror(error) + ")",
                       error == EACCES || error == EPERM
                           ? "make the file readable by this user (chmod a+r), and its folders "
                             "searchable"
                           : "check that the file can be read");
  }
  std::ostringstream buffer;
  buffer << file.rdbuf();
  const std::string text = buffer.str();
  if (text.find('\0') != std::string::npos)
    throw ObjReadError(path + ": contains NUL bytes: a binary file, not a text OBJ file",
                       "name a text OBJ file (v x y z and f i j k lines)");
  return text;
}

// Every polygon fan-triangulated (shapes in file order), indices checked first; `face_of` maps
// each triangle to its OBJ face (0-based, file order). Nothing is merged: duplicate vertices
// stay distinct, so a mesh that relies on them is open.
std::vector<std::array<int, 3>> fan_triangles(const std::vector<tinyobj::shape_t>& shapes, int nv,
                                              const ObjLines& lines, const std::string& path,
                                              std::vector<int>& face_of) {
  std::vector<std::array<int, 3>> triangles;
  int face = 0;
  for (const tinyobj::shape_t& shape : shapes) {
    size_t offset = 0;
    for (const unsigned char corners : shape.mesh.num_face_vertices) {
      std::vector<int> poly;
      for (size_t k = 0; k < corners; ++k) {
        const int v = shape.mesh.indices[offset + k].vertex_index;
        if (v < 0 || v >= nv) {
          const int line =
              face < static_cast<int>(lines.face_line.size()) ? lines.face_line[face] : -1;
          throw GeometryError(path + ": line " + std::to_string(line) + ": face refers to vertex " +
                              std::to_string(v + 1) + ", but the file has " + std::to_string(nv) +
                              " vertices (OBJ counts from 1)");
        }
        poly.push_back(v);
      }
      offset += corners;
      for (size_t k = 1; k + 1 < poly.size(); ++k) {
        triangles.push_back({poly[0], poly[k], poly[k + 1]});
        face_of.push_back(face);
      }
      ++face;
    }
  }
  return triangles;
}

}  // namespace

ConvexPolyhedron load_obj(const std::string& path, bool hull) {
  const std::string text = read_obj_text(path);
  const ObjLines lines = scan_obj_lines(text, path, /*check_faces=*/!hull);

  // Parse without tinyobjloader's triangulation: we fan-triangulate below, after checking the
  // indices (its triangulation reads vertex positions before any bounds check).
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  std::istringstream stream(text);
  if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &stream, nullptr,
                        /*triangulate=*/false))
    throw GeometryError(path + ": " + one_line(first_line(err.empty() ? warn : err)));

  const int nv = static_cast<int>(attrib.vertices.size() / 3);
  std::vector<Vec3> vertices(nv);
  for (int i = 0; i < nv; ++i)
    vertices[i] =
        Vec3(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
  // Coordinates beyond kMaxLength overflow squared lengths and volumes (polyhedron.h).
  for (int i = 0; i < nv; ++i)
    if (!(vertices[i].cwiseAbs().maxCoeff() <= kMaxLength))
      throw ObjReadError(
          path + ": line " +
              std::to_string(i < static_cast<int>(lines.vertex_line.size()) ? lines.vertex_line[i]
                                                                            : -1) +
              ": vertex " + std::to_string(i + 1) + " lies beyond 1e12 m of the origin",
          "scale the mesh to metres, within 1e12 m of its origin");
  if (nv == 0)
    throw ObjReadError(path + ": no vertices (no 'v' lines), not an OBJ mesh",
                       "fix the OBJ file: give its vertices (v x y z) and faces (f i j k)");

  // With hull = true the faces play no part: the hull of the vertices is the shape.
  if (hull) {
    try {
      return convex_hull(vertices);
    } catch (const GeometryError& e) {
      throw GeometryError(path + ": " + e.what());
    }
  }

  // Fan-triangulate, checking indices first.
  std::vector<int> triangle_face;  // triangle -> OBJ face number (0-based, file order)
  const std::vector<std::array<int, 3>> triangles =
      fan_triangles(shapes, nv, lines, path, triangle_face);
  if (triangles.empty()) throw GeometryError(path + ": no faces ('f' lines)");

  ConvexPolyhedron mesh = [&] {
    try {
      return ConvexPolyhedron::from_triangles(vertices, triangles);
    } catch (const GeometryError& e) {
      throw GeometryError(path + ": " + annotate(e.what(), lines, triangle_face));
    }
  }();

  // Self-intersection. A closed, consistently oriented mesh with every vertex behind every face
  // plane has all its triangles on the boundary of its convex hull, facing out; it covers that
  // boundary a whole number of times, and its volume is that number times the hull's. So
  // "self-intersecting" here means "wraps its hull more than once" (two coincident copies, a
  // surface wound twice round an axis): volume > hull volume. The tolerance only has to separate
  // 1 from 2; 1e-6 leaves room for Qhull treating nearly coplanar points as coplanar.
  const double hull_volume = convex_hull(vertices).volume();
  if (mesh.volume() > (1.0 + 1e-6) * hull_volume) {
    std::ostringstream s;
    s << path << ": mesh is self-intersecting: it wraps its convex hull "
      << std::lround(mesh.volume() / hull_volume) << " times (volume " << mesh.volume()
      << " vs hull volume " << hull_volume << ")";
    throw GeometryError(s.str());
  }
  return mesh;
}

}  // namespace rbx
