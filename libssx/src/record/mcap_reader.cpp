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
    In inner(take(num<std::uint32_t>()), offset(), f_);
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

// one record's body, by opcode (messages, schemas, channels: in a chunk or the data section)
void readRecord(McapFile& f, std::uint8_t op, In& in, bool in_chunk);

void readChunk(McapFile& f, In& in) {
  in.num<std::uint64_t>();  // message start time
  in.num<std::uint64_t>();  // message end time
  const auto size = in.num<std::uint64_t>();
  const auto crc = in.num<std::uint32_t>();
  const std::string compression = in.str();
  const std::uint64_t at = in.offset();
  const auto records = in.take(in.num<std::uint64_t>());
  // writers make chunks of a few MiB (ssx: 1 MiB); a size far beyond is a corrupted one, not memory to give
  constexpr std::uint64_t kMaxChunk = std::uint64_t{256} << 20;
  if (size > kMaxChunk)
    in.fail("a chunk of " + std::to_string(size) + " bytes uncompressed (ssx reads chunks of at most 256 MiB)");
  std::vector<std::byte> data;
  if (compression.empty()) {
    if (records.size() != size) in.fail("an uncompressed chunk whose size disagrees with its length (corrupted)");
    data.assign(records.begin(), records.end());
  } else if (compression == "zstd") {
    // the frame says what it holds: it must be the chunk's size (before anything is allocated)
    const unsigned long long content = ZSTD_getFrameContentSize(records.data(), records.size());
    if (content == ZSTD_CONTENTSIZE_ERROR || (content != ZSTD_CONTENTSIZE_UNKNOWN && content != size))
      throw Error(f.file.string() + ": byte " + std::to_string(at) + ": a chunk does not decompress (corrupted)");
    data.resize(static_cast<std::size_t>(size));
    const std::size_t got = ZSTD_decompress(data.data(), data.size(), records.data(), records.size());
    if (ZSTD_isError(got) || got != size)
      throw Error(f.file.string() + ": byte " + std::to_string(at) + ": a chunk does not decompress (corrupted)");
  } else {
    in.fail("a chunk compressed with '" + compression + "' (ssx reads zstd and uncompressed chunks)");
  }
  if (crc != 0 && crc32(data) != crc)
    throw Error(f.file.string() + ": byte " + std::to_string(at) + ": a chunk's CRC does not match (corrupted)");
  ++f.chunks;
  const std::vector<std::byte>& kept = f.decompressed.emplace_back(std::move(data));
  In c(kept, at, f);
  while (c.left() > 0) {
    const auto op = c.num<std::uint8_t>();
    In body(c.take(c.num<std::uint64_t>()), c.offset(), f);
    readRecord(f, op, body, true);
  }
}

void readRecord(McapFile& f, std::uint8_t op, In& in, bool in_chunk) {
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
      m.channel = in.num<std::uint16_t>();
      in.num<std::uint32_t>();  // sequence
      m.log_time = toTime(in.num<std::uint64_t>());
      in.num<std::uint64_t>();  // publish time
      m.data = in.take(in.left());
      if (!f.channels.contains(m.channel)) in.fail("a message on channel " + std::to_string(m.channel) + ", which comes nowhere before it");
      f.messages.push_back(m);
      break;
    }
    case kChunk:
      if (in_chunk) in.fail("a chunk inside a chunk");
      readChunk(f, in);
      break;
    case kAttachment: {
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

McapFile parseMcap(std::vector<std::byte> bytes, const std::filesystem::path& label) {
  McapFile f;
  f.file = label;
  f.raw = std::move(bytes);
  f.size = f.raw.size();
  const std::span<const std::byte> all(f.raw);
  if (all.size() < sizeof kMagic || std::memcmp(all.data(), kMagic, sizeof kMagic) != 0)
    throw Error(label.string() + ": byte 0: not an MCAP file (it does not begin with the MCAP magic)");
  In file(all.subspan(sizeof kMagic), sizeof kMagic, f);
  bool first = true;
  f.data_end = sizeof kMagic;
  while (file.left() > 0) {
    if (file.left() < 9) break;  // a record cut off in its opcode and length: the file ends early
    const std::uint64_t start = file.offset();
    const auto op = file.num<std::uint8_t>();
    const auto length = file.num<std::uint64_t>();
    if (length > file.left()) break;  // cut off: read up to here
    In body(file.take(length), file.offset() - length, f);
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
    } else {
      readRecord(f, op, body, false);
    }
    (void)start;
    first = false;
    f.data_end = file.offset();
  }
  if (first) throw Error(label.string() + ": byte 8: the file ends before its header");
  return f;  // ends early: f.complete stays false
}

McapFile readMcap(const std::filesystem::path& file, std::uint64_t max_bytes) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw Error("cannot open the recording " + file.string() + " (does it exist?)");
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
