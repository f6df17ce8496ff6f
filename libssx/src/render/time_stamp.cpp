#include "render/time_stamp.hpp"

#include <algorithm>
#include <array>
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

namespace ssx::detail {

namespace {

// a 5 x 7 font of the characters a time stamp uses: one row per byte, the leftmost pixel the
// bit of value 16
struct Glyph {
  char c;
  std::array<std::uint8_t, 7> rows;
};
constexpr Glyph kFont[] = {
    {'0', {0b01110, 0b10001, 0b10011, 0b10101, 0b11001, 0b10001, 0b01110}},
    {'1', {0b00100, 0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110}},
    {'2', {0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0b01000, 0b11111}},
    {'3', {0b11111, 0b00010, 0b00100, 0b00010, 0b00001, 0b10001, 0b01110}},
    {'4', {0b00010, 0b00110, 0b01010, 0b10010, 0b11111, 0b00010, 0b00010}},
    {'5', {0b11111, 0b10000, 0b11110, 0b00001, 0b00001, 0b10001, 0b01110}},
    {'6', {0b00110, 0b01000, 0b10000, 0b11110, 0b10001, 0b10001, 0b01110}},
    {'7', {0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b01000, 0b01000}},
    {'8', {0b01110, 0b10001, 0b10001, 0b01110, 0b10001, 0b10001, 0b01110}},
    {'9', {0b01110, 0b10001, 0b10001, 0b01111, 0b00001, 0b00010, 0b01100}},
    {'.', {0b00000, 0b00000, 0b00000, 0b00000, 0b00000, 0b01100, 0b01100}},
    {'-', {0b00000, 0b00000, 0b00000, 0b11111, 0b00000, 0b00000, 0b00000}},
    {'=', {0b00000, 0b00000, 0b11111, 0b00000, 0b11111, 0b00000, 0b00000}},
    {'t', {0b01000, 0b01000, 0b11100, 0b01000, 0b01000, 0b01001, 0b00110}},
    {'s', {0b00000, 0b00000, 0b01110, 0b10000, 0b01110, 0b00001, 0b11110}},
};
constexpr int kGlyphWidth = 5, kGlyphHeight = 7;

const Glyph* glyph(char c) {
  for (const Glyph& g : kFont)
    if (g.c == c) return &g;
  return nullptr;  // a space
}

}  // namespace

std::string timeStampText(Nanoseconds time) {
  // whole milliseconds, rounded, in integers: no floating-point text for a 64-bit count
  const bool negative = time < 0;
  const std::uint64_t magnitude = negative ? 0 - static_cast<std::uint64_t>(time) : static_cast<std::uint64_t>(time);
  const std::uint64_t ms = (magnitude + 500'000) / 1'000'000;
  char text[48];
  std::snprintf(text, sizeof text, "t = %s%" PRIu64 ".%03" PRIu64 " s", negative ? "-" : "", ms / 1000, ms % 1000);
  return text;
}

void stampTime(Image& image, Nanoseconds time) {
  if (image.width <= 0 || image.height <= 0) return;
  const std::string text = timeStampText(time);
  const int k = std::max(1, image.height / 240);  // image pixels per font pixel
  const int pad = 2 * k, advance = (kGlyphWidth + 1) * k;
  const int box_w = 2 * pad + static_cast<int>(text.size()) * advance - k, box_h = 2 * pad + kGlyphHeight * k;
  const int x0 = pad, y0 = pad;  // the box's corner, a margin from the image's
  auto at = [&](int x, int y) { return image.rgb.data() + 3 * (static_cast<std::size_t>(y) * image.width + x); };
  // the box: the picture darkened to 40 %, so that white reads on sky and ground alike
  for (int y = y0; y < std::min(y0 + box_h, image.height); ++y)
    for (int x = x0; x < std::min(x0 + box_w, image.width); ++x)
      for (int c = 0; c < 3; ++c) at(x, y)[c] = static_cast<std::uint8_t>(at(x, y)[c] * 2 / 5);
  for (std::size_t i = 0; i < text.size(); ++i) {
    const Glyph* g = glyph(text[i]);
    if (g == nullptr) continue;
    const int gx = x0 + pad + static_cast<int>(i) * advance, gy = y0 + pad;
    for (int row = 0; row < kGlyphHeight; ++row)
      for (int col = 0; col < kGlyphWidth; ++col) {
        if ((g->rows[static_cast<std::size_t>(row)] & (16 >> col)) == 0) continue;
        for (int dy = 0; dy < k; ++dy)
          for (int dx = 0; dx < k; ++dx) {
            const int x = gx + col * k + dx, y = gy + row * k + dy;
            if (x < image.width && y < image.height) std::fill(at(x, y), at(x, y) + 3, std::uint8_t{255});
          }
      }
  }
}

}  // namespace ssx::detail
