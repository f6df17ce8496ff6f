// JSON text (base/json.cpp): numbers that read back to the same float, no NaN, escaped strings.
#include "base/json.hpp"

#include <catch2/catch.hpp>

#include <charconv>
#include <cmath>
#include <string>

using namespace ssx::detail;

TEST_CASE("json: numbers read back as the same float, JSON has no NaN, strings are escaped", "[json]") {
  for (const double v : {0.0, -1.5, 0.1, 1e-7, 123456.789, -3.4e38}) {
    std::string text;
    appendNumber(text, v);
    float back = 0;
    std::from_chars(text.data(), text.data() + text.size(), back);
    CHECK(back == static_cast<float>(v));
  }
  std::string nan;
  appendNumber(nan, std::nan(""));
  CHECK(nan == "null");
  std::string s;
  appendString(s, "a\"b\\c\nd");
  CHECK(s == R"("a\"b\\c\u000ad")");
}
