// RFC 4648 base64 with padding: pictures and data embedded in self-contained HTML pages.
#pragma once

#include <string>
#include <vector>

namespace rsibr {

std::string base64_encode(const std::vector<unsigned char>& bytes);

}  // namespace rsibr
