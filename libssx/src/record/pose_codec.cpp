#include "record/pose_codec.hpp"

#include <ssx/error.hpp>
#include <ssx/physic_node.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace ssx::detail {

namespace {

constexpr std::size_t kBytesPerBody = 3 * 4 + 4 * 2;

}  // namespace

void encodePoses(std::span<const PhysicNode* const> nodes, std::vector<std::byte>& out) {
  const std::size_t n = nodes.size();
  out.resize(4 + n * kBytesPerBody);
  const auto count = static_cast<std::uint32_t>(n);
  std::memcpy(out.data(), &count, 4);  // (little-endian machines only: x86-64 and arm64)
  // byte planes: byte b of value i of field k at (field start) + b * n + i. Neighbouring robots'
  // high bytes are alike, so the planes compress far better than the values side by side
  std::byte* planes = out.data() + 4;
  for (std::size_t i = 0; i < n; ++i) {
    const Pose p = nodes[i]->pose();
    for (std::size_t k = 0; k < 3; ++k) {
      const auto v = static_cast<float>(p.position[static_cast<Eigen::Index>(k)]);
      std::uint32_t bits = 0;
      std::memcpy(&bits, &v, 4);
      for (std::size_t b = 0; b < 4; ++b) planes[(4 * k + b) * n + i] = static_cast<std::byte>(bits >> (8 * b));
    }
    Quat q = p.orientation.normalized();
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    const double c[4] = {q.w(), q.x(), q.y(), q.z()};
    for (std::size_t k = 0; k < 4; ++k) {
      const auto bits = static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround(std::clamp(c[k], -1.0, 1.0) * 32767.0)));
      for (std::size_t b = 0; b < 2; ++b) planes[(12 + 2 * k + b) * n + i] = static_cast<std::byte>(bits >> (8 * b));
    }
  }
}

std::size_t poseCount(std::span<const std::byte> message) {
  if (message.size() < 4) return 0;
  std::uint32_t n = 0;
  std::memcpy(&n, message.data(), 4);
  return n;
}

void decodePoses(std::span<const std::byte> message, std::vector<float>* positions, std::vector<float>* orientations) {
  const std::size_t n = poseCount(message);
  if (message.size() < 4 || message.size() != 4 + n * kBytesPerBody)
    throw Error("a pose message of " + std::to_string(message.size()) + " bytes does not hold the " + std::to_string(n) +
                " bodies it says (corrupted)");
  const std::byte* planes = message.data() + 4;
  const auto byte = [&](std::size_t plane, std::size_t i) { return static_cast<std::uint32_t>(planes[plane * n + i]); };
  if (positions != nullptr) {
    positions->resize(3 * n);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < 3; ++k) {
        const std::uint32_t bits =
            byte(4 * k, i) | byte(4 * k + 1, i) << 8 | byte(4 * k + 2, i) << 16 | byte(4 * k + 3, i) << 24;
        std::memcpy(&(*positions)[3 * i + k], &bits, 4);
      }
  }
  if (orientations != nullptr) {
    orientations->resize(4 * n);
    for (std::size_t i = 0; i < n; ++i) {
      float q[4];
      double norm = 0;
      for (std::size_t k = 0; k < 4; ++k) {
        const auto v = static_cast<std::int16_t>(static_cast<std::uint16_t>(byte(12 + 2 * k, i) | byte(13 + 2 * k, i) << 8));
        q[k] = static_cast<float>(v) / 32767.0f;
        norm += static_cast<double>(q[k]) * q[k];
      }
      const float scale = norm > 0 ? static_cast<float>(1 / std::sqrt(norm)) : 0.0f;
      for (std::size_t k = 0; k < 4; ++k) (*orientations)[4 * i + k] = norm > 0 ? q[k] * scale : (k == 0 ? 1.0f : 0.0f);
    }
  }
}

}  // namespace ssx::detail
