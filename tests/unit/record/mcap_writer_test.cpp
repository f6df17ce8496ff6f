// The MCAP writer: what it writes reads back record for record (schemas, channels, messages across
// chunks, attachments, metadata), as a complete file; a write that fails says which file.
#include "record/mcap_reader.hpp"
#include "record/mcap_writer.hpp"

#include <ssx/error.hpp>

#include <catch2/catch.hpp>

#include <filesystem>
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

std::string text(std::span<const std::byte> b) { return {reinterpret_cast<const char*>(b.data()), b.size()}; }

}  // namespace

TEST_CASE("mcap writer: schemas, channels, messages over many chunks, attachments and metadata read back",
          "[record][mcap]") {
  const fs::path file = fs::current_path() / "writer_roundtrip.mcap";
  {
    McapWriter w(file, "test", "ssx tests", 256);  // chunks of 256 bytes: many of them
    const auto schema = w.addSchema("demo.Text", "", bytes("plain text"));
    CHECK(schema == 1);
    const auto a = w.addChannel(schema, "/a", "text", {{"k", "v"}});
    const auto b = w.addChannel(0, "/b", "text");
    CHECK((a == 0 && b == 1));
    for (int i = 0; i < 100; ++i) w.addMessage(i % 2 == 0 ? a : b, 1000 * i, bytes("message " + std::to_string(i)));
    w.addAttachment("notes.txt", "text/plain", 5000, bytes("attached"));
    w.addMetadata("about", {{"who", "ssx"}, {"what", "a test"}});
    w.close();
  }
  const McapFile f = readMcap(file);
  CHECK(f.complete);
  CHECK(f.profile == "test");
  CHECK(f.library == "ssx tests");
  CHECK(f.chunks > 10);
  REQUIRE(f.schemas.size() == 1);
  CHECK(f.schemas.at(1).name == "demo.Text");
  CHECK(text(f.schemas.at(1).data) == "plain text");
  REQUIRE(f.channels.size() == 2);
  CHECK(f.channels.at(0).topic == "/a");
  CHECK(f.channels.at(0).metadata.at("k") == "v");
  CHECK(f.channels.at(1).schema == 0);
  REQUIRE(f.messages.size() == 100);
  for (int i = 0; i < 100; ++i) {
    CHECK(f.messages[static_cast<std::size_t>(i)].log_time == 1000 * i);
    CHECK(f.messages[static_cast<std::size_t>(i)].channel == (i % 2 == 0 ? 0 : 1));
    CHECK(text(f.data(f.messages[static_cast<std::size_t>(i)])) == "message " + std::to_string(i));
  }
  REQUIRE(f.attachments.size() == 1);
  CHECK(f.attachments[0].name == "notes.txt");
  CHECK(text(f.attachments[0].data) == "attached");
  CHECK(f.metadata.at("about").at("what") == "a test");
  CHECK(f.channelId("/b") == 1);
  CHECK(f.channelId("/none") == -1);
}

TEST_CASE("mcap writer: a write that fails is an error naming the file", "[record][mcap]") {
  // /dev/full takes the open and refuses every byte
  try {
    McapWriter w("/dev/full", "test", "ssx tests", 64);
    const auto c = w.addChannel(0, "/a", "text");
    for (int i = 0; i < 100; ++i) w.addMessage(c, i, bytes(std::string(100, 'x')));
    w.close();
    FAIL("no error");
  } catch (const Error& e) {
    CHECK_THAT(e.what(), Catch::Contains("cannot write the recording /dev/full"));
  }
  CHECK_THROWS_WITH(McapWriter("/no/such/dir/x.mcap", "t", "t"), Catch::Contains("the recording: cannot create '/no/such/dir/x.mcap'"));
}

TEST_CASE("crc32 is the CRC-32 of zlib, PNG and MCAP", "[record][mcap]") {
  CHECK(crc32(bytes("123456789")) == 0xCBF43926u);  // the standard check value
  CHECK(crc32(bytes("")) == 0u);
  CHECK(crc32(bytes("6789"), crc32(bytes("12345"))) == 0xCBF43926u);  // continued
}
