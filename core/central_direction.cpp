#include "core/central_direction.h"

#include <stdexcept>

namespace rsibr {

const char* to_string(CentralDirection direction) {
  return direction == CentralDirection::Mirror ? "mirror" : "normal";
}

CentralDirection central_direction_from_string(const std::string& name) {
  if (name == "mirror") return CentralDirection::Mirror;
  if (name == "normal") return CentralDirection::Normal;
  throw std::invalid_argument("'" + name + "' is neither mirror nor normal");
}

}  // namespace rsibr
