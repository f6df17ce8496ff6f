// The clock of a recording played on the viewer's page: the wall clock moves it at its speed,
// pause holds it, single steps go one sample on, a seek lands on the sample at or before the time
// asked, and the end holds it.
#include "../../../../plugins/viewer/playback.hpp"

#include <catch2/catch.hpp>

#include <vector>

using ssx::viewer::Playback;

namespace {
// samples every 0.1 s from 1 s to 2 s
std::vector<ssx::Nanoseconds> tenthsFromOne() {
  std::vector<ssx::Nanoseconds> t;
  for (int k = 0; k <= 10; ++k) t.push_back(1'000'000'000 + k * 100'000'000LL);
  return t;
}
}  // namespace

TEST_CASE("playback: paused at the first sample until resumed, then moved by the wall clock at its speed", "[viewer]") {
  Playback p(tenthsFromOne());
  CHECK((p.paused() && p.sample() == 0 && p.time() == 1'000'000'000));
  p.advance(0.5);
  CHECK(p.sample() == 0);
  p.resume();
  p.advance(0.35);
  CHECK((p.time() == 1'350'000'000 && p.sample() == 3));
  REQUIRE(p.setSpeed(2));
  p.advance(0.1);
  CHECK((p.time() == 1'550'000'000 && p.sample() == 5));
  CHECK_FALSE(p.setSpeed(0));
  CHECK_FALSE(p.setSpeed(100));
  CHECK(p.speed() == 2);
}

TEST_CASE("playback: single steps while paused, seeks clamped to the recording, held at the end", "[viewer]") {
  Playback p(tenthsFromOne());
  p.stepOnce();
  p.stepOnce();
  CHECK((p.sample() == 2 && p.time() == 1'200'000'000));
  p.seek(1'770'000'000);
  CHECK((p.sample() == 7 && p.time() == 1'770'000'000));
  p.seek(0);
  CHECK((p.sample() == 0 && p.time() == 1'000'000'000));
  p.seek(5'000'000'000);
  CHECK((p.sample() == 10 && p.time() == 2'000'000'000));
  p.stepOnce();  // none past the last
  CHECK(p.sample() == 10);
  p.resume();  // from the end: from the start again
  CHECK((!p.paused() && p.sample() == 0));
  p.stepOnce();  // not while playing
  CHECK(p.sample() == 0);
  p.advance(3.0);
  CHECK((p.paused() && p.sample() == 10 && p.time() == 2'000'000'000));
}
