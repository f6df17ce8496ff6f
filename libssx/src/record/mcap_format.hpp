#pragma once
// What the MCAP writer and reader share: the magic, the opcodes, and little-endian encoding of the
// specification's primitive types (integers, length-prefixed strings and byte arrays, maps).

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace ssx::detail::mcap {

inline constexpr std::byte kMagic[] = {std::byte{0x89}, std::byte{'M'}, std::byte{'C'},  std::byte{'A'},
                                       std::byte{'P'},  std::byte{'0'}, std::byte{'\r'}, std::byte{'\n'}};

enum Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

/// Appends little-endian values to a byte buffer.
struct Out {
  std::vector<std::byte>& bytes;
  template <class T>
  Out& num(T v) {
    for (std::size_t i = 0; i < sizeof(T); ++i)
      bytes.push_back(static_cast<std::byte>((static_cast<std::uint64_t>(v) >> (8 * i)) & 0xFF));
    return *this;
  }
  Out& raw(const void* data, std::size_t size) {
    const auto* p = static_cast<const std::byte*>(data);
    bytes.insert(bytes.end(), p, p + size);
    return *this;
  }
  Out& str(std::string_view s) {
    num(static_cast<std::uint32_t>(s.size()));
    return raw(s.data(), s.size());
  }
  Out& map(const std::map<std::string, std::string>& m) {
    std::vector<std::byte> body;
    Out inner{body};
    for (const auto& [k, v] : m) inner.str(k).str(v);
    num(static_cast<std::uint32_t>(body.size()));
    return raw(body.data(), body.size());
  }
};

}  // namespace ssx::detail::mcap
