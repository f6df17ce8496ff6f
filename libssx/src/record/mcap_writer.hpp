#pragma once
// A writer of MCAP files (https://mcap.dev/spec, major version 0), written from the specification:
// Debian 12 has no MCAP library. Messages go into zstd-compressed chunks, each followed by its
// message indexes; a chunk reaches the file as soon as it is full or spans a second of log time, so a
// run that is killed leaves a file readable up to its last complete chunk, a second before its end. close() writes the summary section (schemas,
// channels, statistics, chunk, attachment and metadata indexes) and the footer.
//
// Not thread-safe: one thread writes (the recorder's). Every failed write throws Error naming the file.

#include <ssx/types.hpp>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace ssx::detail {

class McapWriter {
 public:
  /// A chunk is written out when it holds this much log time (ns), or chunk_bytes.
  static constexpr std::uint64_t kChunkSpan = 1'000'000'000;

  /// Creates (truncates) `file` and writes the magic and the header (profile, library).
  McapWriter(const std::filesystem::path& file, const std::string& profile, const std::string& library,
             std::size_t chunk_bytes = std::size_t{1} << 20, int zstd_level = 3);
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// A schema (id from 1); written into the data section and, at close, the summary.
  std::uint16_t addSchema(const std::string& name, const std::string& encoding, std::span<const std::byte> data);
  /// A channel on `topic` (id from 0; schema 0: none).
  std::uint16_t addChannel(std::uint16_t schema, const std::string& topic, const std::string& message_encoding,
                           const std::map<std::string, std::string>& metadata = {});
  /// One message, into the open chunk (written out when it holds chunk_bytes).
  void addMessage(std::uint16_t channel, Nanoseconds log_time, std::span<const std::byte> data);
  /// An attachment (written at once, after the open chunk is flushed).
  void addAttachment(const std::string& name, const std::string& media_type, Nanoseconds log_time,
                     std::span<const std::byte> data);
  /// A metadata record.
  void addMetadata(const std::string& name, const std::map<std::string, std::string>& values);
  /// Writes the open chunk out now (and flushes the file to the kernel).
  void flushChunk();
  /// Ends the data section, writes the summary and the footer, closes the file.
  void close();

  /// Bytes written to the file so far.
  std::uint64_t bytesWritten() const noexcept { return offset_; }
  const std::filesystem::path& file() const noexcept { return file_; }

 private:
  struct ChunkIndex {
    std::uint64_t start = 0, end = 0, offset = 0, length = 0, index_length = 0, compressed = 0, uncompressed = 0;
    std::map<std::uint16_t, std::uint64_t> index_offsets;
  };
  struct AttachmentIndex {
    std::uint64_t offset = 0, length = 0, log_time = 0, data_size = 0;
    std::string name, media_type;
  };
  struct MetadataIndex {
    std::uint64_t offset = 0, length = 0;
    std::string name;
  };
  void write(std::span<const std::byte> bytes, bool data_section = true);
  void writeRecord(std::uint8_t opcode, const std::vector<std::byte>& body, bool data_section = true);

  std::filesystem::path file_;
  std::FILE* out_ = nullptr;
  std::uint64_t offset_ = 0;
  std::uint32_t data_crc_ = 0;
  std::size_t chunk_bytes_;
  int zstd_level_;
  // the open chunk: its records, and per channel the (time, offset) of its messages
  std::vector<std::byte> chunk_;
  std::uint64_t chunk_start_ = 0, chunk_end_ = 0;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::vector<std::byte> compressed_;
  // for the summary
  std::vector<std::vector<std::byte>> schemas_, channels_;
  std::map<std::uint16_t, std::uint32_t> sequence_;
  std::map<std::uint16_t, std::uint64_t> channel_counts_;
  std::vector<ChunkIndex> chunks_;
  std::vector<AttachmentIndex> attachments_;
  std::vector<MetadataIndex> metadata_;
  std::uint64_t messages_ = 0, first_time_ = 0, last_time_ = 0;
  bool closed_ = false;
};

/// CRC-32 (the one MCAP, zlib and PNG use) of `data`, continuing from `crc` (0 for a new one).
std::uint32_t crc32(std::span<const std::byte> data, std::uint32_t crc = 0);

struct McapFile;

/// Writes what `f` holds (schemas, channels, metadata, attachments, messages in file order) into a
/// complete new file `out`: a recording cut short made whole, or a test's altered copy. `message`
/// may give a message other bytes (it gets the message's index and bytes), `metadata` may change a
/// metadata record's values.
void rewriteMcap(const McapFile& f, const std::filesystem::path& out,
                 const std::function<std::span<const std::byte>(std::size_t, std::span<const std::byte>)>& message = {},
                 const std::function<void(const std::string&, std::map<std::string, std::string>&)>& metadata = {});

}  // namespace ssx::detail
