// The MCAP reader: a file cut short is read up to its last complete chunk; anything else that is
// wrong is an error naming the file and the byte offset, never a crash.
#include "record/mcap_reader.hpp"
#include "record/mcap_writer.hpp"

#include <ssx/error.hpp>

#include <catch2/catch.hpp>

#include <sys/stat.h>

#include <cstring>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace ssx;
using namespace ssx::detail;
namespace fs = std::filesystem;

namespace {

std::vector<std::byte> bytes(const std::string& s) {
  const auto* p = reinterpret_cast<const std::byte*>(s.data());
  return {p, p + s.size()};
}

// a file of 40 messages in chunks of about 10
std::vector<std::byte> sample(const fs::path& file) {
  {
    McapWriter w(file, "test", "t", 300);
    const auto c = w.addChannel(0, "/a", "text");
    for (int i = 0; i < 40; ++i) w.addMessage(c, i, bytes("message number " + std::to_string(i)));
    w.close();
  }
  std::ifstream in(file, std::ios::binary);
  std::vector<char> raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto* p = reinterpret_cast<const std::byte*>(raw.data());
  return {p, p + raw.size()};
}

}  // namespace

TEST_CASE("mcap reader: a file cut anywhere reads up to its last complete chunk, in order", "[record][mcap]") {
  const std::vector<std::byte> whole = sample(fs::current_path() / "reader_cut.mcap");
  const McapFile full = parseMcap(whole, "whole.mcap");
  REQUIRE(full.complete);
  REQUIRE(full.messages.size() == 40);
  std::size_t previous = 0;
  // from just after the header (magic 8, header 22 bytes) to the last byte
  for (std::size_t cut = 30; cut < whole.size(); cut += 7) {
    const McapFile part = parseMcap(std::vector<std::byte>(whole.begin(), whole.begin() + static_cast<long>(cut)), "cut.mcap");
    INFO("cut at " << cut);
    CHECK_FALSE(part.complete);
    CHECK(part.messages.size() >= previous);  // never fewer for a longer file
    CHECK(part.messages.size() <= 40);
    for (std::size_t i = 0; i < part.messages.size(); ++i) CHECK(part.messages[i].log_time == static_cast<Nanoseconds>(i));
    previous = part.messages.size();
  }
  CHECK(previous == 40);  // cut inside the summary: every chunk is there
  // cut before its header ends: nothing to read
  CHECK_THROWS_WITH(parseMcap(std::vector<std::byte>(whole.begin(), whole.begin() + 20), "short.mcap"),
                    "short.mcap: byte 8: the file ends before its header");
}

TEST_CASE("mcap reader: foreign and corrupted files are errors at a byte offset", "[record][mcap]") {
  const std::vector<std::byte> whole = sample(fs::current_path() / "reader_bad.mcap");
  CHECK_THROWS_WITH(parseMcap(bytes("PK\x03\x04 a zip file"), "x.zip"),
                    "x.zip: byte 0: not an MCAP file (it does not begin with the MCAP magic)");
  CHECK_THROWS_WITH(parseMcap({}, "empty.mcap"), Catch::Contains("empty.mcap: byte 0: not an MCAP file"));
  // a byte changed inside the first chunk's compressed data: it does not decompress or its CRC fails
  std::vector<std::byte> flipped = whole;
  bool found = false;
  for (std::size_t at = 60; at < 120 && !found; ++at) {
    flipped = whole;
    flipped[at] ^= std::byte{0x5A};
    try {
      (void)parseMcap(flipped, "flipped.mcap");
    } catch (const Error& e) {
      const std::string what = e.what();
      CHECK_THAT(what, Catch::StartsWith("flipped.mcap: byte "));
      found = true;
    }
  }
  CHECK(found);
  // every single byte flipped, anywhere: an error or a file read; never a crash (ASan watches)
  for (std::size_t at = 0; at < whole.size(); ++at) {
    flipped = whole;
    flipped[at] ^= std::byte{0xFF};
    try {
      (void)parseMcap(flipped, "f.mcap");
    } catch (const Error&) {
    }
  }
  CHECK(readMcap(fs::current_path() / "reader_bad.mcap").messages.size() == 40);
  CHECK_THROWS_WITH(readMcap(fs::current_path() / "no_such.mcap"), Catch::Contains("cannot open the recording"));
}

TEST_CASE("mcap reader: messages are read back from their chunks one chunk at a time, each byte as written",
          "[record][mcap]") {
  const std::vector<std::byte> whole = sample(fs::current_path() / "reader_lazy.mcap");
  const McapFile f = parseMcap(whole, "lazy.mcap");
  REQUIRE(f.messages.size() == 40);
  CHECK(f.chunk_list.size() >= 4);  // chunks of about 300 bytes
  // in order, back to front and in a stride: every message's bytes are its own
  auto text = [&](std::size_t i) {
    const auto d = f.data(f.messages[i]);
    return std::string(reinterpret_cast<const char*>(d.data()), d.size());
  };
  for (std::size_t i = 0; i < 40; ++i) CHECK(text(i) == "message number " + std::to_string(i));
  for (std::size_t i = 40; i-- > 0;) CHECK(text(i) == "message number " + std::to_string(i));
  for (std::size_t i = 0; i < 40; i += 7) CHECK(text(i) == "message number " + std::to_string(i));
}

TEST_CASE("mcap reader: a small file cannot make it decompress or keep gigabytes", "[record][mcap]") {
  // chunks of 48 MiB of zeros each compress to a few KiB: twelve of them (576 MiB) in a file of
  // about 30 KiB are more than it may decompress to (the larger of 256 MiB and 1,024 times its size)
  const auto zeros = [](const fs::path& file, int chunks) {
    McapWriter w(file, "test", "t", std::size_t{1} << 20);
    const auto c = w.addChannel(0, "/zeros", "bytes");
    const std::vector<std::byte> bytes(std::size_t{48} << 20);
    for (int i = 0; i < chunks; ++i) w.addMessage(c, i, bytes);
    w.close();
  };
  const fs::path file = fs::current_path() / "reader_bomb.mcap";
  zeros(file, 12);
  CHECK(fs::file_size(file) < 100'000);
  CHECK_THROWS_WITH(readMcap(file), Catch::StartsWith(file.string() + ": byte ") &&
                                        Catch::Contains("the file decompresses to more than 256 MiB"));
  // four of them (192 MiB) are read, and a message's bytes come back when asked for
  const fs::path fewer = fs::current_path() / "reader_zeros.mcap";
  zeros(fewer, 4);
  const McapFile f = readMcap(fewer);
  REQUIRE(f.messages.size() == 4);
  CHECK(f.data(f.messages[3]).size() == std::size_t{48} << 20);
  CHECK(f.cache.size() == (std::size_t{48} << 20) + 31);  // one chunk kept: its one message record
  // a chunk that says it holds more than 64 MiB is refused before anything is allocated
  std::vector<std::byte> big = readMcap(fewer).raw;
  // (records from the header on: opcode, length, body; the first chunk's uncompressed size follows its two times)
  std::size_t at = 8;
  while (static_cast<std::uint8_t>(big.at(at)) != 0x06) {
    std::uint64_t length = 0;
    std::memcpy(&length, big.data() + at + 1, 8);
    at += 9 + length;
  }
  const std::uint64_t huge = std::uint64_t{65} << 20;
  std::memcpy(big.data() + at + 1 + 8 + 16, &huge, 8);
  CHECK_THROWS_WITH(parseMcap(big, "big.mcap"), Catch::Contains("(ssx reads chunks of at most 64 MiB)"));
}

TEST_CASE("mcap reader: a FIFO, a device or a directory is refused before it is opened", "[record][mcap]") {
  const fs::path fifo = fs::current_path() / "reader_fifo.mcap";
  fs::remove(fifo);
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  // (opening a FIFO for reading would block until a writer came: the check comes first)
  CHECK_THROWS_WITH(readMcap(fifo), Catch::Contains("not a regular file (a FIFO, a device or a socket"));
  CHECK_THROWS_WITH(readMcap("/dev/zero"), Catch::Contains("not a regular file"));
  CHECK_THROWS_WITH(readMcap(fs::current_path()), Catch::Contains("a directory, not a recording"));
  fs::remove(fifo);
}
