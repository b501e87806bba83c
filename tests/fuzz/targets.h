// Fuzz entry points: one function per target, shared by the libFuzzer drivers (built with
// -DRBX_FUZZ=ON, clang) and the regression replay test (built with the normal compiler, run by
// `./rbx test`), so a crash file replays through exactly the code that found it.
//
// Each entry function takes arbitrary bytes. It returns normally when the code under test
// answered correctly: a result, or the one kind of error its contract allows for bad input. It
// throws InvariantViolation when an answer breaks the contract; any other exception escaping it,
// a crash, a hang or a sanitizer report is a bug too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace rbx::fuzz {

/// A broken invariant of the code under test (not a rejected input). The libFuzzer driver turns
/// it into an abort (a crash file); the replay test into a failure with this message.
class InvariantViolation : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

/// Scene parser: rbx::parse_scene on the bytes as TOML text, named "<dir>/scene/fuzz.toml" in a
/// scratch folder holding the repository's test meshes (so `file = "meshes/cube.obj"` and the
/// bad-input catalogue's OBJ files resolve). Lines after a line "#%set" are --set overrides.
/// Allowed: a Scene, or InputError / GeometryError with a one-line message; an InputError's
/// message starts with the path. A returned Scene has at least one body, all with shapes and
/// finite, positive masses, dt > 0 and duration >= 0.
void scene_parser(const uint8_t* data, size_t size);

/// OBJ loader and mesh validation: the bytes written to a scratch file and read by
/// rbx::load_obj with hull = false and hull = true; and the same bytes decoded as vertex and
/// triangle arrays (see decode_mesh in obj_loader.cpp) for ConvexPolyhedron::from_triangles.
/// Allowed: a polyhedron, or GeometryError (load_obj's message starts with the path, one line).
/// A returned polyhedron is checked: finite vertices, positive volume, closed and consistently
/// oriented, unit outward planes, every vertex behind every plane (convex).
void obj_loader(const uint8_t* data, size_t size);

/// Custom detector on a random convex pair: the bytes decoded as two point sets (convex_hull)
/// and two poses, then rbx::detect with Detector::Faithful and ::Fast. Allowed from
/// convex_hull: GeometryError (the pair is skipped). Checked: a contact has a finite unit
/// normal, a finite depth >= 0 and a finite point; no contact when the world bounding boxes
/// are apart by more than the detector's own tolerance; Fast gives Seed's answer.
void convex_detect(const uint8_t* data, size_t size);

/// One fuzz target: its name (the corpus and regression folder) and its entry function.
struct Target {
  const char* name;
  void (*entry)(const uint8_t* data, size_t size);
};

/// Every target, in the order the `fuzz` action runs them.
const std::vector<Target>& targets();

/// Throws InvariantViolation(what) unless `ok`.
inline void require(bool ok, const std::string& what) {
  if (!ok) throw InvariantViolation(what);
}

}  // namespace rbx::fuzz
