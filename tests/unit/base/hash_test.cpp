#include <ssx/hash.hpp>

#include <catch2/catch.hpp>

#include <cstring>

TEST_CASE("FNV-1a: the published 64-bit test vectors, and numbers hashed byte by byte, low byte first", "[hash]") {
  CHECK(ssx::fnv1a("") == 0xcbf29ce484222325ULL);
  CHECK(ssx::fnv1a("a") == 0xaf63dc4c8601ec8cULL);
  CHECK(ssx::fnv1a("foobar") == 0x85944171f73967e8ULL);
  // continuing a hash is hashing the concatenation
  CHECK(ssx::fnv1a("bar", ssx::fnv1a("foo")) == ssx::fnv1a("foobar"));
  const std::uint64_t bits = 0x0102030405060708ULL;
  const unsigned char low_first[8] = {8, 7, 6, 5, 4, 3, 2, 1};
  CHECK(ssx::fnv1a(bits, ssx::kFnv1aBasis) == ssx::fnv1a(low_first, 8));
}
