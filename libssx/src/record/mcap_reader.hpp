#pragma once
// A reader of the MCAP files McapWriter writes (and of any MCAP file whose chunks are uncompressed
// or zstd): the data section read record by record, chunks decompressed and their CRCs checked.
// A file that ends early (a killed run) is read up to its last complete record and says where it
// ends; anything malformed is an Error naming the file and the byte offset.

#include <ssx/types.hpp>

#include <cstddef>
#include <cstdint>
#include <deque>
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
    Nanoseconds log_time = 0;
    std::span<const std::byte> data;  // into the file's buffers
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
  std::vector<Attachment> attachments;
  std::map<std::string, std::map<std::string, std::string>> metadata;
  std::uint64_t size = 0;             // bytes in the file
  std::uint64_t data_end = 0;         // end of the last complete data record
  bool complete = false;              // data end, summary and footer all there
  std::uint64_t chunks = 0;
  // the bytes the spans point into
  std::vector<std::byte> raw;
  std::deque<std::vector<std::byte>> decompressed;

  /// The channel on `topic`, or -1.
  int channelId(const std::string& topic) const;
};

/// Reads `file` (at most `max_bytes`). Throws Error "FILE: byte N: what is wrong" for a file that is
/// not MCAP, is corrupted, or uses a compression other than zstd or none.
McapFile readMcap(const std::filesystem::path& file, std::uint64_t max_bytes = std::uint64_t{1} << 36);

/// The same from bytes in memory (a fuzz target's input); `label` names it in messages.
McapFile parseMcap(std::vector<std::byte> bytes, const std::filesystem::path& label);

}  // namespace ssx::detail
