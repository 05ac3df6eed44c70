// Compacting a vector in place to the entries a mask keeps, in order. An entry that stays where it
// is is never moved onto itself: a std::vector moved onto itself is left empty.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <utility>
#include <vector>

namespace rsibr {

// Keeps v[i] where keep[i] != 0; keep.size() must equal v.size() (std::invalid_argument).
template <typename T, typename Flag>
void keep_where(std::vector<T>& v, const std::vector<Flag>& keep) {
  if (keep.size() != v.size()) throw std::invalid_argument("keep_where: the mask and the vector differ in size");
  std::size_t w = 0;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (keep[i]) {
      if (w != i) v[w] = std::move(v[i]);
      ++w;
    }
  v.resize(w);
}

}  // namespace rsibr
