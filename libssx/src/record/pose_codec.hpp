#pragma once
// The compact pose message of a recording's /ssx/poses channel (layout in ssx/recording.hpp):
// positions as float32, orientations as int16, each field stored as byte planes.

#include <ssx/types.hpp>

#include <cstddef>
#include <span>
#include <vector>

namespace ssx {
class PhysicNode;
}

namespace ssx::detail {

/// The layout in words, kept in the file as the channel's schema.
inline constexpr const char* kPoseLayout =
    "ssx.poses.v1, little-endian: uint32 N; then the fields float32 x, y, z (m, world frame) and int16 qw, qx, "
    "qy, qz (unit quaternion times 32767, qw >= 0), each as byte planes: byte b of the field's value for body i "
    "at (the field's start) + b * N + i, the fields one after another (x: 4 N bytes, ..., qz: 2 N bytes)";

/// Writes the poses of `nodes` (each a robot's root node, as the snapshot has it) into `out` (resized).
void encodePoses(std::span<const PhysicNode* const> nodes, std::vector<std::byte>& out);

/// Reads a message back: positions (N x 3) and orientations (N x 4, w x y z, normalised). Throws
/// Error when the message's size does not fit its count.
void decodePoses(std::span<const std::byte> message, std::vector<float>* positions, std::vector<float>* orientations);

/// The bytes a message of `bodies` bodies takes.
constexpr std::size_t poseBytes(std::size_t bodies) { return 4 + bodies * (3 * 4 + 4 * 2); }

/// The body count a message holds (0 when it is too short to say).
std::size_t poseCount(std::span<const std::byte> message);

}  // namespace ssx::detail
