// The fuzz targets by name (the registry the drivers and the replay test share).
#include "tests/fuzz/targets.h"

namespace rbx::fuzz {

const std::vector<Target>& targets() {
  static const std::vector<Target> all = {
      {"scene_parser", &scene_parser},
      {"obj_loader", &obj_loader},
      {"convex_detect", &convex_detect},
  };
  return all;
}

}  // namespace rbx::fuzz
