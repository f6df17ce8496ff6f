#pragma once
// A reader of the MCAP files McapWriter writes (and of any MCAP file whose chunks are uncompressed
// or zstd): the data section read record by record, chunks decompressed and their CRCs checked.
// A file that ends early (a killed run) is read up to its last complete record and says where it
// ends; anything malformed is an Error naming the file and the byte offset.
//
// Bounded work per byte read: a chunk is decompressed once to index its messages and then let go;
// a message's bytes are decompressed again when asked for (one chunk kept at a time). A chunk
// holds at most kMaxChunkBytes, and a file may decompress to at most
// max(kMinDecompressedBytes, kMaxExpansion x its size) in all, so that a small file cannot make
// the reader allocate or work through gigabytes (a zstd frame of zeros expands ~30,000-fold).

#include <ssx/types.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace ssx::detail {

struct McapFile {
  struct Schema {
    std::string name, encoding;
    std::vector<std::byte> data;
  };
  struct Channel {
    std::uint16_t schema = 0;
    std::string topic, encoding;
    std::map<std::string, std::string> metadata;
  };
  struct Message {
    std::uint16_t channel = 0;
    std::uint32_t chunk = kNoChunk;  // the chunk it is in (an index into chunks), or kNoChunk
    Nanoseconds log_time = 0;
    std::uint64_t at = 0;    // where its data begins: in the chunk's data, or in the file
    std::uint64_t where = 0; // the byte offset that messages name (the chunk's, plus its place in it)
    std::uint32_t size = 0;  // bytes of data
  };
  static constexpr std::uint32_t kNoChunk = UINT32_MAX;
  struct Chunk {
    std::span<const std::byte> records;  // as in the file (into raw)
    bool zstd = false;
    std::uint64_t size = 0;  // uncompressed
    std::uint32_t crc = 0;
    std::uint64_t at = 0;    // file offset of its records
  };
  struct Attachment {
    std::string name, media_type;
    Nanoseconds log_time = 0;
    std::span<const std::byte> data;
  };
  std::filesystem::path file;
  std::string profile, library;
  std::map<std::uint16_t, Schema> schemas;
  std::map<std::uint16_t, Channel> channels;
  std::vector<Message> messages;  // in file order
  std::vector<Chunk> chunk_list;
  std::vector<Attachment> attachments;
  std::map<std::string, std::map<std::string, std::string>> metadata;
  std::uint64_t size = 0;             // bytes in the file
  std::uint64_t data_end = 0;         // end of the last complete data record
  bool complete = false;              // data end, summary and footer all there
  std::uint64_t chunks = 0;
  // the bytes the spans point into
  std::vector<std::byte> raw;

  /// The channel on `topic`, or -1.
  int channelId(const std::string& topic) const;
  /// A message's bytes: valid until the next call for a message of another chunk (one chunk is
  /// kept decompressed at a time). Not for concurrent use (a Recording serialises its calls).
  std::span<const std::byte> data(const Message& m) const;

  // the chunk last decompressed (data())
  mutable std::uint32_t cached_chunk = kNoChunk;
  mutable std::vector<std::byte> cache;
};

/// The largest chunk read, uncompressed (writers make chunks of a few MiB; ssx 1 MiB).
inline constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{64} << 20;
/// What a file may decompress to in all: max(kMinDecompressedBytes, kMaxExpansion x its size).
inline constexpr std::uint64_t kMinDecompressedBytes = std::uint64_t{256} << 20;
inline constexpr std::uint64_t kMaxExpansion = 1024;

/// Reads `file` (at most `max_bytes`; a regular file: a FIFO, a device or a socket is refused before
/// it is opened). Throws Error "FILE: byte N: what is wrong" for a file that is not MCAP, is
/// corrupted, uses a compression other than zstd or none, or decompresses beyond the bounds above.
McapFile readMcap(const std::filesystem::path& file, std::uint64_t max_bytes = std::uint64_t{1} << 36);

/// The same from bytes in memory (a fuzz target's input); `label` names it in messages.
McapFile parseMcap(std::vector<std::byte> bytes, const std::filesystem::path& label);

}  // namespace ssx::detail
