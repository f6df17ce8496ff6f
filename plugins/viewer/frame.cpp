// The viewer's frames (frame.hpp).
#include "frame.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>

namespace ssx::viewer {

float* beginFrame(std::vector<std::uint8_t>& out, const FrameHeader& h, std::uint32_t n) {
  out.resize(kFrameHeaderBytes + kFramePoseBytes * n);
  std::uint8_t* p = out.data();
  std::memcpy(p, &kFrameMagic, 4), std::memcpy(p + 4, &n, 4), std::memcpy(p + 8, &h.time, 8);
  std::memcpy(p + 16, &h.rate, 4), std::memcpy(p + 20, &h.late, 4), std::memcpy(p + 24, &h.step, 8);
  return reinterpret_cast<float*>(p + kFrameHeaderBytes);  // (a vector's buffer: aligned for floats)
}

void endFrame(std::vector<std::uint8_t>& out, std::uint32_t n, std::string_view trailer) {
  const std::size_t at = kFrameHeaderBytes + kFramePoseBytes * n;
  const std::uint32_t length = static_cast<std::uint32_t>(trailer.size());
  out.resize(at + 4 + trailer.size());
  std::memcpy(out.data() + at, &length, 4);
  std::memcpy(out.data() + at + 4, trailer.data(), trailer.size());
}

std::string trailerJson(double factor, bool paused, const std::string& details, const CommandEcho& echo) {
  std::string out = R"({"run":{"factor":)";
  appendNumber(out, factor);
  out += paused ? R"(,"paused":true})" : R"(,"paused":false})";
  if (echo.sent >= 0) {
    char text[128];
    std::snprintf(text, sizeof text, R"(,"command":{"page":%.0f,"sent":%.3f,"waited_ms":%.3f})", echo.page, echo.sent,
                  echo.waited_ms);
    out += text;
  }
  if (!details.empty()) out += R"(,"details":)" + details;
  return out + "}";
}

void appendNumber(std::string& out, double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", std::isfinite(v) ? v : 0.0);
  out += text;
}

void appendString(std::string& out, std::string_view s) {
  out += '"';
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    out += c;
  }
  out += '"';
}

}  // namespace ssx::viewer
