#pragma once
/// @file
/// FNV-1a, the one hash ssx uses for checksums and fingerprints (saved states, state hashes, sweep
/// fingerprints): fast, byte by byte, the same on every platform.

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace ssx {

/// FNV-1a's 64-bit offset basis: where a hash starts.
inline constexpr std::uint64_t kFnv1aBasis = 0xcbf29ce484222325ULL;

/// FNV-1a (64 bits) of `size` bytes, continuing from `h` (kFnv1aBasis for a new hash).
constexpr std::uint64_t fnv1a(const unsigned char* data, std::size_t size, std::uint64_t h = kFnv1aBasis) {
  for (std::size_t i = 0; i < size; ++i) {
    h ^= data[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

/// FNV-1a (64 bits) of `size` bytes, continuing from `h` (kFnv1aBasis for a new hash).
inline std::uint64_t fnv1a(const std::byte* data, std::size_t size, std::uint64_t h = kFnv1aBasis) {
  return fnv1a(reinterpret_cast<const unsigned char*>(data), size, h);
}

/// FNV-1a (64 bits) of a text's bytes, continuing from `h` (kFnv1aBasis for a new hash).
inline std::uint64_t fnv1a(std::string_view text, std::uint64_t h = kFnv1aBasis) {
  return fnv1a(reinterpret_cast<const unsigned char*>(text.data()), text.size(), h);
}

/// Continues `h` with the 8 bytes of `bits`, least significant first (so a hash of numbers is the
/// same on machines of either byte order).
constexpr std::uint64_t fnv1a(std::uint64_t bits, std::uint64_t h) {
  for (int k = 0; k < 8; ++k) {
    h ^= (bits >> (8 * k)) & 0xffU;
    h *= 0x100000001b3ULL;
  }
  return h;
}

}  // namespace ssx
