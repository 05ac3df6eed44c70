// A shared library opened on first use (dlopen), not when the program starts.
// Why: OpenCV's image codecs (and mrgingham, which links them) bring in about 100 more libraries
// (GDAL, GDCM, the HEIF and JPEG 2000 codecs...). Loading and relocating them took 0.26 s of every
// rsibr start, most of the time of a short command; they are now loaded by the commands that read
// or write an image file, and only then.
// Contract: `soname` is the library's SONAME (the build writes it, see CMakeLists.txt); `symbol`
// returns the address of a mangled name or throws std::runtime_error naming the library and the
// symbol. Thread-safe: the library is opened once, on the first symbol asked for.
#pragma once

#include <mutex>
#include <string>

namespace rsibr {

class LazyLibrary {
 public:
  // `purpose` says in the error what the library is needed for ("reading and writing images").
  LazyLibrary(std::string soname, std::string purpose);
  void* symbol(const char* mangled_name) const;
  // The function `mangled_name` as a pointer of type F (the caller spells F from the library's
  // header, so that a changed signature is a compile error there, see formats/image_codecs.cpp).
  template <class F>
  F function(const char* mangled_name) const {
    return reinterpret_cast<F>(symbol(mangled_name));
  }

 private:
  std::string soname_;
  std::string purpose_;
  mutable std::once_flag opened_;
  mutable void* handle_ = nullptr;  // never closed: the process keeps it, as if it were linked
  mutable std::string error_;       // dlerror() of a failed open, said on every use
};

}  // namespace rsibr
