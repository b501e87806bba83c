// `rbx contacts`' text: one table per touching pair, every backend against the oracle.
#pragma once

#include <ostream>

#include "comparisons/eval/contacts_query.h"
#include "comparisons/scene/scene.h"

namespace rbx {

/// The comparison as text: the first-contact step (with --at first-contact), one table per pair
/// (status, points, normal, depth, point, angle and depth against exact, mark, time), each
/// backend's message, the marks, and why nothing was shown when no pair touches.
void print_contacts(std::ostream& out, const Scene& scene, const ContactsComparison& c);

}  // namespace rbx
