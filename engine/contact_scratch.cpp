#include "engine/contact_scratch.h"

#include "engine/contact_plane_detail.h"

namespace rbx {

ContactScratch::ContactScratch() : lists_(std::make_unique<plane_detail::Scratch>()) {}
ContactScratch::~ContactScratch() = default;
ContactScratch::ContactScratch(ContactScratch&&) noexcept = default;
ContactScratch& ContactScratch::operator=(ContactScratch&&) noexcept = default;

}  // namespace rbx
