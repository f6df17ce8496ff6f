#include "record/mcap_reader.hpp"
#include "record/mcap_format.hpp"
#include "record/mcap_writer.hpp"

#include <ssx/error.hpp>

#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <fstream>

namespace ssx::detail {

using namespace mcap;

namespace {

// reads little-endian fields from a span; every read checked against its end
class In {
 public:
  In(std::span<const std::byte> bytes, std::uint64_t base, const McapFile& f) : bytes_(bytes), base_(base), f_(f) {}
  [[noreturn]] void fail(const std::string& what) const {
    throw Error(f_.file.string() + ": byte " + std::to_string(base_ + at_) + ": " + what);
  }
  std::size_t left() const { return bytes_.size() - at_; }
  std::uint64_t offset() const { return base_ + at_; }
  template <class T>
  T num() {
    if (left() < sizeof(T)) fail("a record ends inside a field (corrupted)");
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) v |= static_cast<std::uint64_t>(bytes_[at_ + i]) << (8 * i);
    at_ += sizeof(T);
    return static_cast<T>(v);
  }
  std::span<const std::byte> take(std::uint64_t n) {
    if (n > left()) fail("a length of " + std::to_string(n) + " runs past the end of its record (corrupted)");
    const auto s = bytes_.subspan(at_, static_cast<std::size_t>(n));
    at_ += static_cast<std::size_t>(n);
    return s;
  }
  std::string str() {
    const auto s = take(num<std::uint32_t>());
    return std::string(reinterpret_cast<const char*>(s.data()), s.size());
  }
  std::map<std::string, std::string> map() {
    const auto length = num<std::uint32_t>();
    const std::uint64_t at = offset();
    In inner(take(length), at, f_);
    std::map<std::string, std::string> m;
    while (inner.left() > 0) {
      std::string k = inner.str();
      m[std::move(k)] = inner.str();
    }
    return m;
  }

 private:
  std::span<const std::byte> bytes_;
  std::uint64_t base_;
  std::size_t at_ = 0;
  const McapFile& f_;
};

Nanoseconds toTime(std::uint64_t t) {
  return static_cast<Nanoseconds>(std::min<std::uint64_t>(t, static_cast<std::uint64_t>(INT64_MAX)));
}

// what the file may still decompress to, and how many messages it may still index
struct Budget {
  std::uint64_t bytes = 0;
  std::uint64_t messages = 0;
};

// one record's body, by opcode (messages, schemas, channels: in a chunk or the data section)
void readRecord(McapFile& f, std::uint8_t op, In& in, std::uint32_t chunk, std::uint64_t data_base, Budget& budget);

// decompresses chunk `k` into `out` (its CRC checked); throws Error at its offset
void decompress(const McapFile& f, const McapFile::Chunk& c, std::vector<std::byte>& out) {
  const auto fail = [&](const std::string& what) {
    throw Error(f.file.string() + ": byte " + std::to_string(c.at) + ": " + what);
  };
  if (!c.zstd) {
    out.assign(c.records.begin(), c.records.end());
  } else {
    // the frame says what it holds: it must be the chunk's size (before anything is allocated)
    const unsigned long long content = ZSTD_getFrameContentSize(c.records.data(), c.records.size());
    if (content == ZSTD_CONTENTSIZE_ERROR || (content != ZSTD_CONTENTSIZE_UNKNOWN && content != c.size))
      fail("a chunk does not decompress (corrupted)");
    out.resize(static_cast<std::size_t>(c.size));
    const std::size_t got = ZSTD_decompress(out.data(), out.size(), c.records.data(), c.records.size());
    if (ZSTD_isError(got) || got != c.size) fail("a chunk does not decompress (corrupted)");
  }
  if (c.crc != 0 && crc32(out) != c.crc) fail("a chunk's CRC does not match (corrupted)");
}

void readChunk(McapFile& f, In& in, Budget& budget, std::vector<std::byte>& scratch) {
  in.num<std::uint64_t>();  // message start time
  in.num<std::uint64_t>();  // message end time
  McapFile::Chunk c;
  c.size = in.num<std::uint64_t>();
  c.crc = in.num<std::uint32_t>();
  const std::string compression = in.str();
  c.at = in.offset();
  c.records = in.take(in.num<std::uint64_t>());
  // writers make chunks of a few MiB (ssx: 1 MiB); a size far beyond is a corrupted one, not memory to give
  if (c.size > kMaxChunkBytes)
    in.fail("a chunk of " + std::to_string(c.size) + " bytes uncompressed (ssx reads chunks of at most " +
            std::to_string(kMaxChunkBytes >> 20) + " MiB)");
  if (compression.empty()) {
    if (c.records.size() != c.size) in.fail("an uncompressed chunk whose size disagrees with its length (corrupted)");
  } else if (compression == "zstd") {
    c.zstd = true;
  } else {
    in.fail("a chunk compressed with '" + compression + "' (ssx reads zstd and uncompressed chunks)");
  }
  if (c.zstd && c.size > budget.bytes)
    throw Error(f.file.string() + ": byte " + std::to_string(c.at) + ": the file decompresses to more than " +
                std::to_string(std::max(kMinDecompressedBytes, kMaxExpansion * f.size) >> 20) +
                " MiB (a reader takes the larger of " + std::to_string(kMinDecompressedBytes >> 20) + " MiB and " +
                std::to_string(kMaxExpansion) + " times a file's size; ssx's own recordings stay far below): a "
                "corrupted or hostile file");
  budget.bytes -= c.zstd ? c.size : 0;
  decompress(f, c, scratch);
  if (f.chunk_list.size() >= McapFile::kNoChunk) in.fail("too many chunks");
  const auto index = static_cast<std::uint32_t>(f.chunk_list.size());
  f.chunk_list.push_back(c);
  ++f.chunks;
  In r(scratch, c.at, f);
  while (r.left() > 0) {
    const auto op = r.num<std::uint8_t>();
    const auto length = r.num<std::uint64_t>();
    const std::uint64_t body_file = r.offset();
    In body(r.take(length), body_file, f);
    readRecord(f, op, body, index, body_file - c.at, budget);
  }
}

void readRecord(McapFile& f, std::uint8_t op, In& in, std::uint32_t chunk, std::uint64_t data_base, Budget& budget) {
  const bool in_chunk = chunk != McapFile::kNoChunk;
  switch (op) {
    case kSchema: {
      const auto id = in.num<std::uint16_t>();
      McapFile::Schema s;
      s.name = in.str();
      s.encoding = in.str();
      const auto data = in.take(in.num<std::uint32_t>());
      s.data.assign(data.begin(), data.end());
      if (id != 0) f.schemas[id] = std::move(s);
      break;
    }
    case kChannel: {
      const auto id = in.num<std::uint16_t>();
      McapFile::Channel c;
      c.schema = in.num<std::uint16_t>();
      c.topic = in.str();
      c.encoding = in.str();
      c.metadata = in.map();
      if (c.schema != 0 && !f.schemas.contains(c.schema)) in.fail("a channel names schema " + std::to_string(c.schema) + ", which comes nowhere before it");
      f.channels[id] = std::move(c);
      break;
    }
    case kMessage: {
      McapFile::Message m;
      m.where = in.offset();
      m.channel = in.num<std::uint16_t>();
      in.num<std::uint32_t>();  // sequence
      m.log_time = toTime(in.num<std::uint64_t>());
      in.num<std::uint64_t>();  // publish time
      if (in.left() > UINT32_MAX) in.fail("a message of more than 4 GiB");
      m.size = static_cast<std::uint32_t>(in.left());
      // (in a chunk, `in` counts from the chunk's file offset: its place in the chunk's data is data_base + 22)
      m.at = in_chunk ? data_base + 22 : in.offset();
      m.chunk = chunk;
      in.take(in.left());
      if (!f.channels.contains(m.channel)) in.fail("a message on channel " + std::to_string(m.channel) + ", which comes nowhere before it");
      if (budget.messages == 0)
        in.fail("more messages than this reader indexes for a file of this size (a corrupted or hostile file)");
      --budget.messages;
      f.messages.push_back(m);
      break;
    }
    case kChunk:
      if (in_chunk) in.fail("a chunk inside a chunk");
      break;  // (read by the caller)
    case kAttachment: {
      if (in_chunk) break;  // (chunks hold schemas, channels and messages only)
      McapFile::Attachment a;
      a.log_time = toTime(in.num<std::uint64_t>());
      in.num<std::uint64_t>();  // create time
      a.name = in.str();
      a.media_type = in.str();
      a.data = in.take(in.num<std::uint64_t>());
      in.num<std::uint32_t>();  // crc (not checked: the data is checked where it is used, a state by its own checksum)
      f.attachments.push_back(std::move(a));
      break;
    }
    case kMetadata: {
      if (in_chunk) break;
      std::string name = in.str();
      f.metadata[std::move(name)] = in.map();
      break;
    }
    default:
      break;  // message indexes, and records of later versions: skipped
  }
}

}  // namespace

int McapFile::channelId(const std::string& topic) const {
  for (const auto& [id, c] : channels)
    if (c.topic == topic) return id;
  return -1;
}

std::span<const std::byte> McapFile::data(const Message& m) const {
  if (m.chunk == kNoChunk) return std::span<const std::byte>(raw).subspan(m.at, m.size);
  if (cached_chunk != m.chunk) {
    cached_chunk = kNoChunk;
    decompress(*this, chunk_list.at(m.chunk), cache);
    cached_chunk = m.chunk;
  }
  return std::span<const std::byte>(cache).subspan(m.at, m.size);
}

McapFile parseMcap(std::vector<std::byte> bytes, const std::filesystem::path& label) {
  McapFile f;
  f.file = label;
  f.raw = std::move(bytes);
  f.size = f.raw.size();
  const std::span<const std::byte> all(f.raw);
  if (all.size() < sizeof kMagic || std::memcmp(all.data(), kMagic, sizeof kMagic) != 0)
    throw Error(label.string() + ": byte 0: not an MCAP file (it does not begin with the MCAP magic)");
  In file(all.subspan(sizeof kMagic), sizeof kMagic, f);
  Budget budget;
  budget.bytes = std::max(kMinDecompressedBytes, kMaxExpansion * f.size);
  // an index entry per message: at most max(64 MiB, 16 x the file's size) of them
  budget.messages = std::max(std::uint64_t{64} << 20, 16 * f.size) / sizeof(McapFile::Message);
  std::vector<std::byte> scratch;
  bool first = true;
  f.data_end = sizeof kMagic;
  while (file.left() > 0) {
    if (file.left() < 9) break;  // a record cut off in its opcode and length: the file ends early
    const auto op = file.num<std::uint8_t>();
    const auto length = file.num<std::uint64_t>();
    if (length > file.left()) break;  // cut off: read up to here
    const std::uint64_t body_at = file.offset();
    In body(file.take(length), body_at, f);
    if (first && op != kHeader) body.fail("the first record is not a header (corrupted)");
    if (op == kHeader) {
      if (!first) body.fail("a second header (corrupted)");
      f.profile = body.str();
      f.library = body.str();
    } else if (op == kDataEnd) {
      f.data_end = file.offset();
      // the summary and the footer follow; the file is complete when it ends with footer and magic
      const auto tail = all.size() >= 8 + 29 ? all.subspan(all.size() - 8 - 29) : std::span<const std::byte>{};
      f.complete = !tail.empty() && static_cast<std::uint8_t>(tail[0]) == kFooter &&
                   std::memcmp(all.data() + all.size() - 8, kMagic, 8) == 0;
      return f;
    } else if (op == kChunk) {
      readChunk(f, body, budget, scratch);
    } else {
      readRecord(f, op, body, McapFile::kNoChunk, 0, budget);
    }
    first = false;
    f.data_end = file.offset();
  }
  if (first) throw Error(label.string() + ": byte 8: the file ends before its header");
  return f;  // ends early: f.complete stays false
}

McapFile readMcap(const std::filesystem::path& file, std::uint64_t max_bytes) {
  // never opened unless a regular file: a FIFO would block the open, a device never end
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (!std::filesystem::exists(status)) throw Error("cannot open the recording " + file.string() + " (does it exist?)");
  if (std::filesystem::is_directory(status)) throw Error(file.string() + ": a directory, not a recording: give an .mcap file");
  if (!std::filesystem::is_regular_file(status))
    throw Error(file.string() + ": not a regular file (a FIFO, a device or a socket has no end or no fixed content): "
                "give a recording (.mcap) file");
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw Error("cannot open the recording " + file.string() + " (is it readable?)");
  const auto size = static_cast<std::uint64_t>(in.tellg());
  if (size > max_bytes)
    throw Error(file.string() + ": " + std::to_string(size) + " bytes, more than the " + std::to_string(max_bytes) +
                " this reader takes");
  std::vector<std::byte> bytes(static_cast<std::size_t>(size));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
  if (!in) throw Error("cannot read the recording " + file.string());
  return parseMcap(std::move(bytes), file);
}

}  // namespace ssx::detail
