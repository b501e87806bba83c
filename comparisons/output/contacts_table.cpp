#include "comparisons/output/contacts_table.h"

#include "comparisons/output/query_cells.h"
#include "comparisons/output/table.h"
#include "engine/format.h"

namespace rbx {

void print_contacts(std::ostream& out, const Scene& scene, const ContactsComparison& c) {
  if (c.at_first && c.contact_step >= 0)
    out << "first contact: step " << c.contact_step
        << ", t = " << fmt_num(c.contact_step * scene.sim.dt)
        << " s (the custom engine's motion up to there; the exact oracle's test)\n";
  for (const ContactsPair& p : c.pairs) {
    const ContactPoint* t = deepest(p.truth_run.result);
    out << "\npair " << p.a << "-" << p.b << " (normal from " << p.b << " toward " << p.a
        << "); exact: "
        << (t ? "depth " + fmt_num(t->depth) + ", normal " + fmt_vec(t->normal) : "no contact")
        << "\n";
    Table table({"backend", "status", "points", "normal", "depth", "point", "angle vs exact",
                 "depth - exact", "coverage", "mark", "time (µs)", "25-75 %", "cold call (µs)"});
    for (const ContactsRow& r : p.rows) {
      const ContactPoint* q = deepest(r.run.result);
      std::vector<std::string> cells = {r.backend,
                                        to_string(r.run.result.status),
                                        std::to_string(r.run.result.contacts.size()),
                                        q ? fmt_vec(q->normal) : "-",
                                        q ? fmt_num(q->depth, 5) : "-",
                                        q ? fmt_vec(q->point) : "-",
                                        r.angle,
                                        r.depth_diff,
                                        r.cover ? fmt_num(r.cover->coverage_err / r.size, 3) : "-",
                                        mark_cell(r.mark)};
      for (std::string& c : timing_cells(r.run.timing)) cells.push_back(std::move(c));
      table.add(std::move(cells));
    }
    table.print(out);
    for (const ContactsRow& r : p.rows)
      if (!r.run.result.message.empty())
        out << "  " << r.backend << ": " << r.run.result.message << "\n";
  }
  for (const std::string& m : c.marks) out << "  " << m << "\n";
  if (!c.pairs.empty()) {
    out << "\ncoverage: how far the points fall short of the exact contact patch, the largest "
           "distance from a corner of the patch to the hull of the points across the normal, "
           "relative to the smaller body (0: they span it; docs/contact_manifold.md)\n";
    out << kQueryTimingNote;
    return;
  }
  if (!c.at_first)
    out << "no pair of bodies touches at t = 0 (--at first-contact queries where one first "
           "does)\n";
  else
    out << "no pair of bodies touches within the run (" << scene.sim.steps()
        << " steps of the custom engine"
        << (c.stop_reason.empty() ? "" : "; it stopped: " + c.stop_reason) << ")\n";
}

}  // namespace rbx
