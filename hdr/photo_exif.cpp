#include "hdr/photo_exif.h"

#include "formats/heif_image.h"

namespace rsibr {

Exiv2::ExifData read_photo_exif(const std::string& file) {
  if (is_heif_file(file)) {
    Exiv2::ExifData exif;
    const std::vector<unsigned char> tiff = heif_exif(file);
    if (!tiff.empty()) Exiv2::ExifParser::decode(exif, tiff.data(), static_cast<uint32_t>(tiff.size()));
    return exif;
  }
  auto image = Exiv2::ImageFactory::open(file);
  image->readMetadata();
  return image->exifData();
}

}  // namespace rsibr
