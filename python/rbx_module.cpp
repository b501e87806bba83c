// The C++ side of the Python module `rbx` (python/rbx/__init__.py): the command line run in this
// process, the registry, and a researcher's Python functions registered as backends. Everything
// a Python user sees is shaped in python/rbx/; this file only crosses the language boundary.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "comparisons/cli/commands.h"
#include "reference/backend.h"
#include "reference/custom.h"

namespace py = pybind11;

namespace rbx {

namespace {

// A stream buffer that keeps what is written and also passes it on (stderr stays live: progress
// lines of long commands reach the user as they come).
class TeeBuffer : public std::streambuf {
 public:
  explicit TeeBuffer(std::streambuf* pass) : pass_(pass) {}
  std::string text;

 protected:
  int overflow(int c) override {
    if (c == EOF) return 0;
    text.push_back(static_cast<char>(c));
    return pass_ ? pass_->sputc(static_cast<char>(c)) : c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    text.append(s, static_cast<size_t>(n));
    return pass_ ? pass_->sputn(s, n) : n;
  }
  int sync() override { return pass_ ? pass_->pubsync() : 0; }

 private:
  std::streambuf* pass_;
};

// `rbx ARGS...` in this process: (exit code, standard output, standard error). Standard output
// is kept, not shown; standard error is kept, and shown as it comes when `show_stderr` (the
// progress lines of long commands). The GIL is released: the commands run their own threads and
// child processes, and a registered Python backend takes it back.
py::tuple command_line_in_process(const std::vector<std::string>& args, bool show_stderr) {
  std::vector<std::string> argv_text = {"rbx"};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  TeeBuffer out(nullptr), err(show_stderr ? std::cerr.rdbuf() : nullptr);
  int code = 0;
  {
    py::gil_scoped_release release;
    std::streambuf* old_out = std::cout.rdbuf(&out);
    std::streambuf* old_err = std::cerr.rdbuf(&err);
    try {
      code = command_line(static_cast<int>(argv_text.size()), argv.data());
    } catch (...) {
      std::cout.rdbuf(old_out);
      std::cerr.rdbuf(old_err);
      throw;
    }
    std::cout.rdbuf(old_out);
    std::cerr.rdbuf(old_err);
  }
  return py::make_tuple(code, out.text, err.text);
}

// Every registry row as a dict.
py::list backend_rows() {
  py::list rows;
  for (const Backend& b : backends()) {
    py::dict d;
    d["name"] = b.name;
    d["description"] = b.description;
    d["contact"] = static_cast<bool>(b.contact);
    d["dynamics"] = static_cast<bool>(b.dynamics);
    d["distance"] = static_cast<bool>(b.distance);
    d["toi"] = static_cast<bool>(b.toi);
    d["mass"] = static_cast<bool>(b.mass);
    d["library"] = b.library;
    d["friction"] = b.friction;
    d["user"] = b.user;
    d["colour"] = b.style.colour;
    d["marker"] = b.style.marker;
    rows.append(d);
  }
  return rows;
}

py::array_t<double> vec_array(const Vec3& v) {
  py::array_t<double> a(3);
  for (int k = 0; k < 3; ++k) a.mutable_at(k) = v[k];
  return a;
}

// A body as a registered contact function receives it: world-frame vertices and the hull's
// triangles, the centre of mass and the orientation (w, x, y, z).
py::dict body_dict(const RigidBody& b) {
  const std::vector<Vec3>& local = b.shape->vertices();
  py::array_t<double> vertices({static_cast<py::ssize_t>(local.size()), py::ssize_t{3}});
  auto v = vertices.mutable_unchecked<2>();
  for (size_t i = 0; i < local.size(); ++i) {
    const Vec3 w = b.position + b.orientation * local[i];
    for (int k = 0; k < 3; ++k) v(static_cast<py::ssize_t>(i), k) = w[k];
  }
  const auto& tris = b.shape->triangles();
  py::array_t<long> faces({static_cast<py::ssize_t>(tris.size()), py::ssize_t{3}});
  auto f = faces.mutable_unchecked<2>();
  for (size_t i = 0; i < tris.size(); ++i)
    for (int k = 0; k < 3; ++k) f(static_cast<py::ssize_t>(i), k) = tris[i][k];
  py::dict d;
  d["name"] = b.name;
  d["vertices"] = vertices;
  d["faces"] = faces;
  d["position"] = vec_array(b.position);
  py::array_t<double> q(4);
  q.mutable_at(0) = b.orientation.w();
  q.mutable_at(1) = b.orientation.x();
  q.mutable_at(2) = b.orientation.y();
  q.mutable_at(3) = b.orientation.z();
  d["orientation"] = q;
  d["static"] = b.is_static;
  return d;
}

// Three finite numbers from a Python sequence, or a message naming what was wrong.
Vec3 vec_of(const py::handle& x, const std::string& what) {
  std::vector<double> v;
  try {
    v = py::cast<std::vector<double>>(x);
  } catch (const py::cast_error&) {
    throw std::runtime_error(what + " is not a sequence of 3 numbers");
  }
  if (v.size() != 3)
    throw std::runtime_error(what + " has " + std::to_string(v.size()) + " numbers, not 3");
  const Vec3 r(v[0], v[1], v[2]);
  if (!r.allFinite()) throw std::runtime_error(what + " is not finite");
  return r;
}

// What a registered contact function returned, as contacts; std::runtime_error names the fault.
ContactResult contacts_of(const py::handle& out) {
  if (!py::isinstance<py::list>(out) && !py::isinstance<py::tuple>(out))
    throw std::runtime_error("returned " + std::string(py::str(out.get_type().attr("__name__"))) +
                             ", expected a list of {\"point\", \"normal\", \"depth\"} dicts");
  ContactResult r;
  size_t k = 0;
  for (const py::handle& item : out) {
    const std::string at = "contact " + std::to_string(k++);
    if (!py::isinstance<py::dict>(item))
      throw std::runtime_error(at + " is " +
                               std::string(py::str(item.get_type().attr("__name__"))) +
                               ", expected a dict with point, normal, depth");
    const py::dict d = py::reinterpret_borrow<py::dict>(item);
    for (const char* key : {"point", "normal", "depth"})
      if (!d.contains(key)) throw std::runtime_error(at + " has no \"" + key + "\"");
    ContactPoint c;
    c.point = vec_of(d["point"], at + " point");
    c.normal = vec_of(d["normal"], at + " normal");
    if (std::abs(c.normal.norm() - 1.0) > 1e-6)
      throw std::runtime_error(at + " normal is not a unit vector (length " +
                               std::to_string(c.normal.norm()) + ")");
    try {
      c.depth = py::cast<double>(d["depth"]);
    } catch (const py::cast_error&) {
      throw std::runtime_error(at + " depth is not a number");
    }
    if (!std::isfinite(c.depth)) throw std::runtime_error(at + " depth is not finite");
    // A depth is an overlap: a separated pair has no contact to return (the registered
    // function's contract, docstring of register_contact_backend).
    if (c.depth < 0)
      throw std::runtime_error(at + " depth " + std::to_string(c.depth) +
                               " is negative (the overlap, >= 0; return no contact when apart)");
    c.feature = d.contains("feature") ? py::str(d["feature"]).cast<std::string>() : "";
    r.contacts.push_back(c);
  }
  return r;
}

// The message of the Python exception being handled: "TypeError: text".
std::string python_message(py::error_already_set& e) {
  std::string type = "exception";
  try {
    type = py::str(e.type().attr("__name__"));
  } catch (...) {
  }
  return type + ": " + std::string(py::str(e.value()));
}

// The Python callable kept for the life of the process: never destroyed, so no reference is
// dropped after the interpreter is gone (the registry outlives it).
std::shared_ptr<py::object> kept(py::function fn) {
  return std::shared_ptr<py::object>(new py::object(std::move(fn)), [](py::object*) {});
}

void register_contact(const std::string& name, const std::string& description, py::function fn) {
  auto f = kept(std::move(fn));
  Backend b;
  b.name = name;
  b.description = description;
  b.contact = [f, name](const RigidBody& a, const RigidBody& bb) -> ContactResult {
    py::gil_scoped_acquire gil;
    try {
      return contacts_of((*f)(body_dict(a), body_dict(bb)));
    } catch (py::error_already_set& e) {
      return {Status::Error, name + ": " + python_message(e), {}};
    } catch (const std::exception& e) {
      return {Status::Error, name + ": " + e.what(), {}};
    }
  };
  b.library = true;  // a user's code: isolated with a deadline, like an outside library
  register_backend(std::move(b));
}

// A body's state as a response function receives it (world frame).
py::dict state_dict(const RigidBody& b) {
  py::dict d = body_dict(b);
  d["mass"] = b.mass;
  d["inverse_mass"] = b.inverse_mass;
  py::array_t<double> inv({3, 3});
  const Mat3 iw = b.inverse_inertia_world();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) inv.mutable_at(i, j) = iw(i, j);
  d["inverse_inertia"] = inv;
  d["velocity"] = vec_array(b.velocity);
  d["angular_velocity"] = vec_array(b.angular_velocity);
  return d;
}

void register_response(const std::string& name, const std::string& description, py::function fn) {
  auto f = kept(std::move(fn));
  Backend b;
  b.name = name;
  b.description = description;
  const ResponseFn response = [f, name](const RigidBody& a, const RigidBody& bb,
                                        const ContactPoint& c, double restitution) -> Vec3 {
    py::gil_scoped_acquire gil;
    py::dict contact;
    contact["point"] = vec_array(c.point);
    contact["normal"] = vec_array(c.normal);
    contact["depth"] = c.depth;
    contact["feature"] = c.feature;
    try {
      return vec_of((*f)(state_dict(a), state_dict(bb), contact, restitution),
                    "the impulse it returned");
    } catch (py::error_already_set& e) {
      throw std::runtime_error(name + ": " + python_message(e));
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(name + ": " + e.what());
    }
  };
  b.dynamics = [response](const WorldDefinition& scene, const DynamicsOptions& opt) {
    return custom_seed_dynamics_with(scene, opt, response);
  };
  b.library = true;
  b.friction = false;  // the seed's contacts are single points; friction is the function's own
  register_backend(std::move(b));
}

}  // namespace

}  // namespace rbx

PYBIND11_MODULE(_rbx, m) {
  m.doc() = "The C++ side of the rbx module (use `import rbx`).";
  m.def("command_line", &rbx::command_line_in_process, py::arg("args"),
        py::arg("show_stderr") = false,
        "Runs `rbx ARGS...` in this process: (exit code, stdout text, stderr text).");
  m.def("backends", &rbx::backend_rows, "Every registry row as a dict.");
  m.def("register_contact_backend", &rbx::register_contact, py::arg("name"), py::arg("description"),
        py::arg("fn"), "Adds a Python contact function as a backend.");
  m.def("register_response_backend", &rbx::register_response, py::arg("name"),
        py::arg("description"), py::arg("fn"), "Adds a Python collision response as a backend.");
  m.def("unregister_backend", &rbx::unregister_backend, py::arg("name"),
        "Removes a backend registered from Python.");
}
