#pragma once
// The compact pose message of a recording's /ssx/poses channel (layout in ssx/recording.hpp):
// positions as float32 planes, orientations as int16 planes.

#include <ssx/types.hpp>

#include <cstddef>
#include <span>
#include <vector>

namespace ssx {
class Environment;
}

namespace ssx::detail {

/// The layout in words, kept in the file as the channel's schema.
inline constexpr const char* kPoseLayout =
    "ssx.poses.v1, little-endian: uint32 N; float32 x[N]; float32 y[N]; float32 z[N] (m, world frame); "
    "int16 qw[N]; int16 qx[N]; int16 qy[N]; int16 qz[N] (unit quaternion times 32767, qw >= 0)";

/// Writes the poses of `bodies` (body indices) of `env` into `out` (resized).
void encodePoses(const Environment& env, std::span<const int> bodies, std::vector<std::byte>& out);

/// Reads a message back: positions (N x 3) and orientations (N x 4, w x y z, normalised). Throws
/// Error when the message's size does not fit its count.
void decodePoses(std::span<const std::byte> message, std::vector<float>* positions, std::vector<float>* orientations);

/// The body count a message holds (0 when it is too short to say).
std::size_t poseCount(std::span<const std::byte> message);

}  // namespace ssx::detail
