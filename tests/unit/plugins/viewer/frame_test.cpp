// The viewer's frames: the documented layout (header, poses, trailer with its length), a buffer
// reused for a smaller frame holding nothing of the larger one, and the trailer's JSON.
#include "../../../../plugins/viewer/frame.hpp"

#include <catch2/catch.hpp>

#include <chrono>
#include <cstring>
#include <limits>
#include <string>

using namespace ssx::viewer;

namespace {
template <class T>
T at(const std::vector<std::uint8_t>& b, std::size_t offset) {
  T v;
  std::memcpy(&v, b.data() + offset, sizeof v);
  return v;
}
}  // namespace

TEST_CASE("viewer frame: header, 28 bytes per pose, then the trailer's length and text", "[viewer]") {
  std::vector<std::uint8_t> b;
  float* f = beginFrame(b, {12.5, 0.75f, 3, 6250}, 2);
  for (int i = 0; i < 14; ++i) f[i] = static_cast<float>(i) + 0.5f;
  endFrame(b, 2, R"({"run":{}})");
  REQUIRE(b.size() == 32 + 2 * 28 + 4 + 10);
  CHECK(at<std::uint32_t>(b, 0) == 0x46585353);
  CHECK(std::string(reinterpret_cast<const char*>(b.data()), 4) == "SSXF");
  CHECK(at<std::uint32_t>(b, 4) == 2);
  CHECK(at<double>(b, 8) == 12.5);
  CHECK(at<float>(b, 16) == 0.75f);
  CHECK(at<std::uint32_t>(b, 20) == 3);
  CHECK(at<std::uint64_t>(b, 24) == 6250);
  CHECK(at<float>(b, 32) == 0.5f);
  CHECK(at<float>(b, 32 + 13 * 4) == 13.5f);
  CHECK(at<std::uint32_t>(b, 88) == 10);
  CHECK(std::string(reinterpret_cast<const char*>(b.data()) + 92, 10) == R"({"run":{}})");
  // the same buffer, a frame of one pose and an empty trailer: nothing left of the first
  beginFrame(b, {1, 1, 0, 1}, 1)[0] = 7;
  endFrame(b, 1, "");
  CHECK(b.size() == 32 + 28 + 4);
  CHECK(at<std::uint32_t>(b, 60) == 0);
}

TEST_CASE("viewer frame trailer: the run's pace, a command's echo once given, the details when any", "[viewer]") {
  CHECK(trailerJson(0, false, "") == R"({"run":{"factor":0,"paused":false}})");
  CHECK(trailerJson(4, true, "[1]") == R"({"run":{"factor":4,"paused":true},"details":[1]})");
  CHECK(trailerJson(1, false, "", {12345, 678.25, 1.5}) ==
        R"({"run":{"factor":1,"paused":false},"command":{"page":12345,"sent":678.250,"waited_ms":1.500}})");
  std::string text;
  appendString(text, "a\"b\\c\n");
  CHECK(text == R"("a\"b\\c")");
  text.clear();
  appendNumber(text, std::numeric_limits<double>::infinity());
  CHECK(text == "0");
}

TEST_CASE("viewer pacing: 30 frames a second from ticks of 20 ms, and no burst after a pause", "[viewer]") {
  using Clock = FramePacer::Clock;
  using std::chrono::milliseconds;
  const Clock::time_point start{std::chrono::hours(5)};
  FramePacer pacer(std::chrono::duration<double>(1.0 / 30));
  auto frames_between = [](FramePacer& paced, Clock::time_point from, int ticks) {  // a tick each 20 ms
    int sent = 0;
    for (int k = 0; k < ticks; ++k) {
      const Clock::time_point now = from + milliseconds(20) * k;
      if (paced.due(now)) paced.sent(now), ++sent;
    }
    return sent;
  };
  CHECK(pacer.due(start));                         // the first frame at once
  CHECK(frames_between(pacer, start, 150) == 90);  // 3 s: 30 a second (a period after each frame sent: 25)
  // a pause of 2 s, then ticks again: one frame at once, then 30 a second, none owed for the pause
  const Clock::time_point later = start + milliseconds(5000);
  CHECK(pacer.due(later));
  CHECK(frames_between(pacer, later, 50) == 30);
  // no period (a page that asked for no rate): every tick
  FramePacer every;
  CHECK(frames_between(every, start, 10) == 10);
}
