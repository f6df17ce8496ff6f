#include "record/mcap_writer.hpp"
#include "record/mcap_format.hpp"
#include "record/mcap_reader.hpp"

#include <ssx/error.hpp>
#include <ssx/run_files.hpp>

#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace ssx::detail {

using namespace mcap;

std::uint32_t crc32(std::span<const std::byte> data, std::uint32_t crc) {
  // zlib's crc32 takes at most 4 GiB at a time
  const auto* p = reinterpret_cast<const Bytef*>(data.data());
  std::size_t left = data.size();
  uLong c = crc;
  while (left > 0) {
    const auto n = static_cast<uInt>(std::min<std::size_t>(left, 1u << 30));
    c = ::crc32(c, p, n);
    p += n;
    left -= n;
  }
  return static_cast<std::uint32_t>(c);
}

McapWriter::McapWriter(const std::filesystem::path& file, const std::string& profile, const std::string& library,
                       std::size_t chunk_bytes, int zstd_level)
    : file_(file), chunk_bytes_(chunk_bytes), zstd_level_(zstd_level) {
  try {
    out_ = openOutputFile(file);  // (locked while written: a second run recording into it is refused)
  } catch (const Error& e) {
    throw Error(std::string("the recording: ") + e.what());
  }
  write(kMagic);
  std::vector<std::byte> header;
  Out{header}.str(profile).str(library);
  writeRecord(kHeader, header);
}

McapWriter::~McapWriter() {
  if (out_ != nullptr) std::fclose(out_);
}

void McapWriter::write(std::span<const std::byte> bytes, bool data_section) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), out_) != bytes.size())
    throw Error("cannot write the recording " + file_.string() + " (at byte " + std::to_string(offset_) +
                "): " + std::strerror(errno));
  if (data_section) data_crc_ = crc32(bytes, data_crc_);
  offset_ += bytes.size();
}

void McapWriter::writeRecord(std::uint8_t opcode, const std::vector<std::byte>& body, bool data_section) {
  std::vector<std::byte> head;
  Out{head}.num(opcode).num(static_cast<std::uint64_t>(body.size()));
  write(head, data_section);
  write(body, data_section);
}

std::uint16_t McapWriter::addSchema(const std::string& name, const std::string& encoding,
                                    std::span<const std::byte> data) {
  const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
  std::vector<std::byte> body;
  Out{body}.num(id).str(name).str(encoding).num(static_cast<std::uint32_t>(data.size())).raw(data.data(), data.size());
  writeRecord(kSchema, body);
  schemas_.push_back(std::move(body));
  return id;
}

std::uint16_t McapWriter::addChannel(std::uint16_t schema, const std::string& topic, const std::string& message_encoding,
                                     const std::map<std::string, std::string>& metadata) {
  const auto id = static_cast<std::uint16_t>(channels_.size());
  std::vector<std::byte> body;
  Out{body}.num(id).num(schema).str(topic).str(message_encoding).map(metadata);
  writeRecord(kChannel, body);
  channels_.push_back(std::move(body));
  channel_counts_[id] = 0;
  return id;
}

void McapWriter::addMessage(std::uint16_t channel, Nanoseconds log_time, std::span<const std::byte> data) {
  const auto time = static_cast<std::uint64_t>(log_time);
  if (chunk_.empty()) chunk_start_ = chunk_end_ = time;
  chunk_start_ = std::min(chunk_start_, time);
  chunk_end_ = std::max(chunk_end_, time);
  chunk_index_[channel].emplace_back(time, chunk_.size());
  Out o{chunk_};
  o.num(static_cast<std::uint8_t>(kMessage)).num(static_cast<std::uint64_t>(2 + 4 + 8 + 8 + data.size()));
  o.num(channel).num(sequence_[channel]++).num(time).num(time).raw(data.data(), data.size());
  if (messages_ == 0) first_time_ = last_time_ = time;
  first_time_ = std::min(first_time_, time);
  last_time_ = std::max(last_time_, time);
  ++messages_;
  ++channel_counts_[channel];
  // full, or holding a second of log time: a killed run loses at most that
  if (chunk_.size() >= chunk_bytes_ || chunk_end_ - chunk_start_ >= kChunkSpan) flushChunk();
}

void McapWriter::flushChunk() {
  if (!chunk_.empty()) {
    const std::uint32_t crc = crc32(chunk_);
    compressed_.resize(ZSTD_compressBound(chunk_.size()));
    const std::size_t size = ZSTD_compress(compressed_.data(), compressed_.size(), chunk_.data(), chunk_.size(), zstd_level_);
    if (ZSTD_isError(size))
      throw Error("cannot compress a chunk of the recording " + file_.string() + ": " + ZSTD_getErrorName(size));
    std::vector<std::byte> body;
    Out{body}
        .num(chunk_start_)
        .num(chunk_end_)
        .num(static_cast<std::uint64_t>(chunk_.size()))
        .num(crc)
        .str("zstd")
        .num(static_cast<std::uint64_t>(size))
        .raw(compressed_.data(), size);
    ChunkIndex index;
    index.start = chunk_start_;
    index.end = chunk_end_;
    index.offset = offset_;
    index.compressed = size;
    index.uncompressed = chunk_.size();
    writeRecord(kChunk, body);
    index.length = offset_ - index.offset;
    // the message indexes, one per channel, right after their chunk
    const std::uint64_t indexes_start = offset_;
    for (const auto& [channel, entries] : chunk_index_) {
      std::vector<std::byte> mi;
      Out o{mi};
      o.num(channel).num(static_cast<std::uint32_t>(entries.size() * 16));
      for (const auto& [time, at] : entries) o.num(time).num(at);
      index.index_offsets[channel] = offset_;
      writeRecord(kMessageIndex, mi);
    }
    index.index_length = offset_ - indexes_start;
    chunks_.push_back(std::move(index));
    chunk_.clear();
    chunk_index_.clear();
  }
  if (std::fflush(out_) != 0)
    throw Error("cannot write the recording " + file_.string() + ": " + std::strerror(errno));
}

void McapWriter::addAttachment(const std::string& name, const std::string& media_type, Nanoseconds log_time,
                               std::span<const std::byte> data) {
  flushChunk();
  std::vector<std::byte> body;
  const auto time = static_cast<std::uint64_t>(log_time);
  Out{body}.num(time).num(time).str(name).str(media_type).num(static_cast<std::uint64_t>(data.size())).raw(data.data(),
                                                                                                           data.size());
  const std::uint32_t crc = crc32(body);
  Out{body}.num(crc);
  AttachmentIndex index{offset_, 0, time, data.size(), name, media_type};
  writeRecord(kAttachment, body);
  index.length = offset_ - index.offset;
  attachments_.push_back(std::move(index));
  if (std::fflush(out_) != 0)
    throw Error("cannot write the recording " + file_.string() + ": " + std::strerror(errno));
}

void McapWriter::addMetadata(const std::string& name, const std::map<std::string, std::string>& values) {
  flushChunk();
  std::vector<std::byte> body;
  Out{body}.str(name).map(values);
  MetadataIndex index{offset_, 0, name};
  writeRecord(kMetadata, body);
  index.length = offset_ - index.offset;
  metadata_.push_back(std::move(index));
}

void McapWriter::close() {
  if (closed_) return;
  closed_ = true;
  flushChunk();
  std::vector<std::byte> data_end;
  Out{data_end}.num(data_crc_);
  writeRecord(kDataEnd, data_end);

  // the summary: groups of records, each group's place in a summary offset record
  const std::uint64_t summary_start = offset_;
  std::uint32_t summary_crc = 0;
  std::vector<std::pair<std::uint8_t, std::pair<std::uint64_t, std::uint64_t>>> groups;
  auto summaryRecord = [&](std::uint8_t opcode, const std::vector<std::byte>& body) {
    std::vector<std::byte> record;
    Out{record}.num(opcode).num(static_cast<std::uint64_t>(body.size())).raw(body.data(), body.size());
    summary_crc = crc32(record, summary_crc);
    write(record, false);
  };
  auto group = [&](std::uint8_t opcode, const std::vector<std::vector<std::byte>>& bodies) {
    if (bodies.empty()) return;
    const std::uint64_t start = offset_;
    for (const auto& b : bodies) summaryRecord(opcode, b);
    groups.push_back({opcode, {start, offset_ - start}});
  };
  group(kSchema, schemas_);
  group(kChannel, channels_);
  {
    std::vector<std::byte> stats;
    Out o{stats};
    o.num(messages_)
        .num(static_cast<std::uint16_t>(schemas_.size()))
        .num(static_cast<std::uint32_t>(channels_.size()))
        .num(static_cast<std::uint32_t>(attachments_.size()))
        .num(static_cast<std::uint32_t>(metadata_.size()))
        .num(static_cast<std::uint32_t>(chunks_.size()))
        .num(first_time_)
        .num(last_time_);
    std::vector<std::byte> counts;
    for (const auto& [channel, count] : channel_counts_) Out{counts}.num(channel).num(count);
    o.num(static_cast<std::uint32_t>(counts.size())).raw(counts.data(), counts.size());
    group(kStatistics, {stats});
  }
  std::vector<std::vector<std::byte>> records;
  for (const ChunkIndex& c : chunks_) {
    std::vector<std::byte> b;
    Out o{b};
    o.num(c.start).num(c.end).num(c.offset).num(c.length);
    std::vector<std::byte> offsets;
    for (const auto& [channel, at] : c.index_offsets) Out{offsets}.num(channel).num(at);
    o.num(static_cast<std::uint32_t>(offsets.size())).raw(offsets.data(), offsets.size());
    o.num(c.index_length).str("zstd").num(c.compressed).num(c.uncompressed);
    records.push_back(std::move(b));
  }
  group(kChunkIndex, records);
  records.clear();
  for (const AttachmentIndex& a : attachments_) {
    std::vector<std::byte> b;
    Out{b}.num(a.offset).num(a.length).num(a.log_time).num(a.log_time).num(a.data_size).str(a.name).str(a.media_type);
    records.push_back(std::move(b));
  }
  group(kAttachmentIndex, records);
  records.clear();
  for (const MetadataIndex& m : metadata_) {
    std::vector<std::byte> b;
    Out{b}.num(m.offset).num(m.length).str(m.name);
    records.push_back(std::move(b));
  }
  group(kMetadataIndex, records);
  const std::uint64_t summary_offset_start = offset_;
  for (const auto& [opcode, place] : groups) {
    std::vector<std::byte> b;
    Out{b}.num(opcode).num(place.first).num(place.second);
    summaryRecord(kSummaryOffset, b);
  }
  // the footer: its crc covers the summary up to and including the footer's two offsets
  std::vector<std::byte> footer_head;
  Out{footer_head}.num(static_cast<std::uint8_t>(kFooter)).num(std::uint64_t{20}).num(summary_start).num(summary_offset_start);
  summary_crc = crc32(footer_head, summary_crc);
  std::vector<std::byte> footer = footer_head;
  Out{footer}.num(summary_crc);
  write(footer, false);
  write(kMagic, false);
  if (std::fclose(out_) != 0) {
    out_ = nullptr;
    throw Error("cannot write the recording " + file_.string() + ": " + std::strerror(errno));
  }
  out_ = nullptr;
}

void rewriteMcap(const McapFile& f, const std::filesystem::path& out,
                 const std::function<std::span<const std::byte>(std::size_t, std::span<const std::byte>)>& message,
                 const std::function<void(const std::string&, std::map<std::string, std::string>&)>& metadata) {
  McapWriter w(out, f.profile, f.library);
  // schemas and channels get their ids in order, as the writer gave them: re-added in id order
  std::map<std::uint16_t, std::uint16_t> schema_ids, channel_ids;
  for (const auto& [id, s] : f.schemas) schema_ids[id] = w.addSchema(s.name, s.encoding, s.data);
  for (const auto& [id, c] : f.channels)
    channel_ids[id] = w.addChannel(c.schema == 0 ? 0 : schema_ids.at(c.schema), c.topic, c.encoding, c.metadata);
  for (auto [name, values] : f.metadata) {
    if (metadata) metadata(name, values);
    w.addMetadata(name, values);
  }
  for (const auto& a : f.attachments) w.addAttachment(a.name, a.media_type, a.log_time, a.data);
  for (std::size_t i = 0; i < f.messages.size(); ++i) {
    const McapFile::Message& m = f.messages[i];
    const std::span<const std::byte> data = f.data(m);
    w.addMessage(channel_ids.at(m.channel), m.log_time, message ? message(i, data) : data);
  }
  w.close();
}

}  // namespace ssx::detail
