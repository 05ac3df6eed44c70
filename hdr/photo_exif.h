// A photo's EXIF as exiv2 decodes it, whatever the container: exiv2's own reader (JPEG, TIFF,
// PNG, most RAW files), or for HEIF/HEIC the Exif block that libheif reads (formats/heif_image.h),
// decoded by exiv2's parser. Throws Exiv2::Error as exiv2 does for a file it cannot read, and
// std::runtime_error("<file>: ...") for a broken HEIF.
#pragma once

#include <exiv2/exiv2.hpp>

#include <string>

namespace rsibr {

Exiv2::ExifData read_photo_exif(const std::string& file);

}  // namespace rsibr
