#include "core/lazy_library.h"

#include <dlfcn.h>

#include <stdexcept>
#include <utility>

namespace rsibr {

LazyLibrary::LazyLibrary(std::string soname, std::string purpose)
    : soname_(std::move(soname)), purpose_(std::move(purpose)) {}

void* LazyLibrary::symbol(const char* mangled_name) const {
  std::call_once(opened_, [&] {
    handle_ = dlopen(soname_.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle_) {
      const char* why = dlerror();
      error_ = why ? why : "unknown error";
    }
  });
  if (!handle_) throw std::runtime_error("cannot load " + soname_ + " (needed for " + purpose_ + "): " + error_);
  void* address = dlsym(handle_, mangled_name);
  if (!address) {
    throw std::runtime_error(soname_ + " has no symbol " + mangled_name + " (needed for " + purpose_ +
                             "): not the version rsibr was built with");
  }
  return address;
}

}  // namespace rsibr
