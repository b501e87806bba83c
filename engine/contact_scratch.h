// The scratch of the extended engine's contact queries: the lists that the plane's searches, the
// inner polytope and the contact region fill on every query. Its owner hands it down, as Box2D's
// step context carries its arena and Jolt's queries take a TempAllocator: a world's step keeps
// one, a caller of find_contact one per thread of queries, so the lists are allocated once per
// owner and reused, and no query keeps anything between calls that its caller cannot see. Answers
// never depend on it. One thread at a time may use a scratch.
#pragma once

#include <memory>

namespace rbx {

namespace plane_detail {
struct Scratch;
}

class ContactScratch {
 public:
  ContactScratch();
  ~ContactScratch();
  ContactScratch(ContactScratch&&) noexcept;
  ContactScratch& operator=(ContactScratch&&) noexcept;

  /// The lists themselves (engine/contact_plane_detail.h), for the queries' own files.
  plane_detail::Scratch& lists() { return *lists_; }

 private:
  std::unique_ptr<plane_detail::Scratch> lists_;
};

}  // namespace rbx
