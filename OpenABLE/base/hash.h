// Hashes of bytes that stay the same across compilers and machines (files on disk name and
// check their contents with them: the descriptor cache, saved maps).
#pragma once

#include <cstddef>
#include <cstdint>

namespace openable {

// FNV-1a, 64 bits (Fowler, Noll, Vo: offset basis 14695981039346656037, prime
// 1099511628211), continued from `h`. Stable across compilers and machines, unlike std::hash.
inline constexpr std::uint64_t kFnv1a64Offset = 14695981039346656037ull;
inline std::uint64_t Fnv1a64(const void* data, size_t size, std::uint64_t h = kFnv1a64Offset) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t k = 0; k < size; ++k) {
    h ^= p[k];
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace openable
