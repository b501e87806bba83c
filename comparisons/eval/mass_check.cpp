// The mass check: each library's mass properties of a hull against the exact solid's.
#include "comparisons/eval/evaluator.h"

namespace rbx::eval_detail {

void Evaluator::mass_check() {
  std::vector<const Backend*> libs;
  const std::vector<std::string> wanted =
      select_backends(scene_, opt_.backends, Capability::Contact, table_);
  for (const Backend& b : table_)
    if (b.mass &&
        (opt_.backends.empty() || std::find(wanted.begin(), wanted.end(), b.name) != wanted.end()))
      libs.push_back(&b);
  for (size_t i = 0; i < inputs_.size(); ++i) {
    const RigidBody& body = inputs_[i];
    const MassProperties exact = solid_mass_properties(*body.shape, body.mass);
    const double volume = body.shape->volume();
    const double size = body_size(body);
    auto record = [&](const std::string& name, const MassResult& r) {
      set_status(name, r.status, r.message);
      if (r.status != Status::Ok) return;
      metric("mass", name, body.name, "mass_err_rel", std::abs(r.mass - exact.mass) / exact.mass,
             "exact solid");
      metric("mass", name, body.name, "com_err_rel",
             (r.center_of_mass - exact.center_of_mass).norm() / size, "exact solid");
      metric("mass", name, body.name, "inertia_err_rel",
             (r.inertia - exact.inertia).norm() / exact.inertia.norm(), "exact solid");
      if (r.volume >= 0)
        metric("mass", name, body.name, "volume_err_rel", std::abs(r.volume - volume) / volume,
               "exact solid");
      // Marks: above 1 % a different model or a defect (✗); above 1e-6, more than the
      // round-off of a library storing vertices in float (MuJoCo), a deviation (~).
      const double worst = std::max({std::abs(r.mass - exact.mass) / exact.mass,
                                     (r.center_of_mass - exact.center_of_mass).norm() / size,
                                     (r.inertia - exact.inertia).norm() / exact.inertia.norm()});
      const std::string what =
          name + " on " + body.name + ": mass properties off by " + fmt_num(worst, 3) +
          " (relative, worst of mass, centre of mass and inertia) against the exact solid" +
          (name == "custom-seed" ? " (the seed's point masses at the vertices)" : "");
      if (worst > 1e-2)
        out_.disagreements.push_back(what);
      else if (worst > 1e-6)
        out_.deviations.push_back(what);
    };
    // The engines' own rows: `custom` with the model it simulates this body with (the
    // scene's mass_model, solid by default), `custom-seed` with the seed's point masses at the
    // vertices.
    const MassProperties own = mass_properties(*body.shape, body.mass, scene_.bodies[i].mass_model);
    record("custom", {Status::Ok, "", own.mass, -1.0, own.center_of_mass, own.inertia});
    const MassProperties seed = vertex_mass_properties(*body.shape, body.mass);
    record("custom-seed", {Status::Ok, "", seed.mass, -1.0, seed.center_of_mass, seed.inertia});
    for (const Backend* b : libs) {
      MassResult r;
      const bool cacheable = cache_.enabled() && ResultCache::caches(b->name);
      const std::string key = cacheable ? cache_.mass_key(b->name, body) : std::string();
      std::optional<CachedResult<MassResult>> hit;
      if (cacheable) hit = cache_.load_mass(key);
      if (hit) {
        r = hit->result;
        backend_json(b->name)["cached"] = true;
      } else {
        r = isolated_mass(b->name, CallDeadlines{}.mass_s, [&] { return b->mass(body); });
        if (cacheable) cache_.store(key, r, 0.0);
      }
      record(b->name, r);
    }
  }
  // A backend named with --backends that computes no mass properties of its own is reported,
  // not dropped (the contract: named but not applicable -> unsupported).
  const bool named = !opt_.backends.empty() || !scene_.backends.empty();
  for (const std::string& name : wanted)
    if (named && name != "custom" && name != "custom-seed" && !backend(name).mass)
      set_status(name, Status::Unsupported,
                 name +
                     " computes no mass properties of its own (every backend is given the "
                     "exact solid values)");
  out_.skipped.push_back(
      "mass: custom is the model it simulates with, custom-seed the seed's vertex model; ode has "
      "no hull mass routine");
}

}  // namespace rbx::eval_detail
