// The simulated time burnt into scene camera frames: its text and where it is drawn.
#include "render/time_stamp.hpp"

#include <catch2/catch.hpp>

#include <cstdint>
#include <limits>

using namespace ssx;
using ssx::detail::stampTime;
using ssx::detail::timeStampText;

namespace {

Image grey(int width, int height) {
  Image im;
  im.width = width;
  im.height = height;
  im.rgb.assign(static_cast<std::size_t>(width) * height * 3, 128);
  return im;
}

// the box the stamp changed: its right and bottom edges (exclusive), and how many pixels are white
struct Changed {
  int right = 0, bottom = 0, white = 0, other = 0;
};
Changed changed(const Image& im) {
  Changed c;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const std::uint8_t* p = im.pixel(x, y);
      if (p[0] == 128 && p[1] == 128 && p[2] == 128) continue;
      c.right = std::max(c.right, x + 1);
      c.bottom = std::max(c.bottom, y + 1);
      if (p[0] == 255 && p[1] == 255 && p[2] == 255)
        ++c.white;
      else if (p[0] == 51 && p[1] == 51 && p[2] == 51)  // 128 darkened to 40 %
        continue;
      else
        ++c.other;
    }
  return c;
}

}  // namespace

TEST_CASE("time stamp: the text is the time in seconds to the millisecond, rounded", "[render][time_stamp]") {
  CHECK(timeStampText(0) == "t = 0.000 s");
  CHECK(timeStampText(1'250'000'000) == "t = 1.250 s");
  CHECK(timeStampText(2'000'000) == "t = 0.002 s");
  CHECK(timeStampText(1'999'600'000) == "t = 2.000 s");    // rounded, carried into the seconds
  CHECK(timeStampText(3'600'000'499'999) == "t = 3600.000 s");
  CHECK(timeStampText(-1'500'000'000) == "t = -1.500 s");
  CHECK(timeStampText(std::numeric_limits<Nanoseconds>::max()) == "t = 9223372036.855 s");
}

TEST_CASE("time stamp: white letters on a darkened box in the top-left corner, the rest untouched",
          "[render][time_stamp]") {
  Image im = grey(640, 480);
  stampTime(im, 12'345'000'000);
  const Changed c = changed(im);
  CHECK(c.other == 0);      // only darkened or white pixels
  CHECK(c.white > 100);     // letters, 2 x 2 pixels per font pixel at 480 rows
  CHECK(c.right < 640 / 3);  // a corner, not a banner
  CHECK(c.bottom <= 4 + 2 * 4 + 7 * 2);
  // another time writes other letters; a larger image larger ones
  Image other = grey(640, 480);
  stampTime(other, 98'765'000'000);
  CHECK(other.rgb != im.rgb);
  Image large = grey(1920, 1080);
  stampTime(large, 12'345'000'000);
  CHECK(changed(large).white == c.white * 4);  // 4 x 4 pixels per font pixel at 1080 rows
}

TEST_CASE("time stamp: an image smaller than the text is clipped, not overrun", "[render][time_stamp]") {
  for (int side : {1, 3, 8, 20}) {
    Image im = grey(side, side);
    stampTime(im, 1'000'000'000);
    CHECK(im.rgb.size() == static_cast<std::size_t>(side) * side * 3);
    CHECK(changed(im).other == 0);
  }
  Image empty;
  stampTime(empty, 0);
  CHECK(empty.rgb.empty());
}
