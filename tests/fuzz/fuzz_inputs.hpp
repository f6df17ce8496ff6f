#pragma once
// What the fuzz targets do with one input, shared by the libFuzzer binaries (tests/fuzz/*_fuzz.cpp)
// and by the regression test that replays every input in tests/data/fuzz/<target>/ under ctest.
//
// Each function either returns (the input was accepted and ran, or was refused the expected way:
// SceneError while loading, ssx::Error while running or restoring) or lets anything else escape:
// a crash, a sanitizer report or another exception is a finding.
#include <cstddef>
#include <cstdint>
#include <span>

namespace ssx::fuzz {

/// A scene, optionally followed by a line "----" and an artifact file (the scene reaches it as
/// `<type name="a" file="a.xml"/>`). Loaded only: a scene may ask for millions of robots.
void sceneInput(std::span<const std::uint8_t> data);

/// An artifact file, placed three times in a fixed scene with a ground, loaded and stepped.
void artifactInput(std::span<const std::uint8_t> data);

/// A URDF file, placed twice in a fixed scene with a ground, loaded and stepped (meshes it names
/// are looked for beside it: the fuzzer reaches the mesh reader through names it finds).
void robotInput(std::span<const std::uint8_t> data);

/// Up to four parameter assignments to the plugins of an mk_quad (driver quadrotor, sensors imu
/// and pose): lines of [plugin byte][parameter byte][value text]. Loaded, then flown 0.2 s.
void parameterInput(std::span<const std::uint8_t> data);

/// A buffer for Environment::restoreState of a fixed scene (tests/fuzz/state_scene.xml). One that
/// starts with "SSXSTATE" is used as it is; anything else is a payload that gets a valid header
/// (so that the fuzzer reaches past the checksum). After a restore that is accepted, 20 steps.
void stateInput(std::span<const std::uint8_t> data);

/// The ssx command's arguments, separated by NUL bytes (at most 64), parsed as the command parses
/// them and nothing run. What parsing accepts must be in the ranges the options promise (a
/// std::logic_error otherwise: a finding); what it refuses gets exit status 2.
void commandLineInput(std::span<const std::uint8_t> data);

/// A recording (MCAP), read as `ssx inspect` and `ssx replay` read one (the MCAP reader), and its
/// pose messages decoded. A file that is refused is an ssx::Error.
void recordingInput(std::span<const std::uint8_t> data);

}  // namespace ssx::fuzz
