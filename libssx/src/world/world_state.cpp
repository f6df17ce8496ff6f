// Saving and restoring the world: everything that determines the future, in one versioned,
// checksummed buffer.
//
// Layout: "SSXSTATE", format version (u32), reserved (u32), scene fingerprint (u64), payload size
// (u64), FNV-1a of the payload (u64); then the payload: step count, the engine's name and its block, the
// snapshot (body states with accelerations, the velocities before the last step), the command
// buffers, the joints' motor commands, the run-time joints, the varied constants, every plugin's random stream (the
// world's plugin table, in order), then one block per plugin (driver first, then sensors, artifact by artifact: what it
// saved), one per extension, the ghosts' block, and the artifacts out of the world (their count, then their indices).
#include "world/ghosts.hpp"
#include "world/phases.hpp"
#include "world/neighbor_index.hpp"
#include "render/scene_cameras.hpp"
#include "engines/state_checks.hpp"
#include "world/world.hpp"

#include <ssx/environment.hpp>
#include <ssx/hash.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace ssx {

namespace {

constexpr char kMagic[8] = {'S', 'S', 'X', 'S', 'T', 'A', 'T', 'E'};
// 4: run-time joints (PhysicNode::attach); 5: the engine's name (states restore on the engine that
// saved them), the run-time joints' kinds; 6: the varied constants (Environment::vary); 7: the
// same payload under a faster checksum (stateChecksum; format 6's states are still read); 8: the
// artifacts out of the world (Environment::despawn; formats 6 and 7 had none)
constexpr std::uint32_t kFormatVersion = 8;
constexpr std::size_t kHeaderSize = 8 + 4 + 4 + 8 + 8 + 8;

// the format of a state checkState passed
std::uint32_t formatOf(std::span<const std::byte> state) {
  std::uint32_t version = 0;
  std::memcpy(&version, state.data() + 8, 4);
  return version;
}

void writeBody(StateWriter& out, const BodyState& s) {
  out.write(s.pose);
  out.write(s.linear_velocity);
  out.write(s.angular_velocity);
  out.write(s.linear_acceleration);
  out.write(s.angular_acceleration);
}

void readBody(StateReader& in, BodyState& s) {
  in.read(s.pose);
  in.read(s.linear_velocity);
  in.read(s.angular_velocity);
  in.read(s.linear_acceleration);
  in.read(s.angular_acceleration);
}

// a block: its size first, filled in once written
template <class Fill>
void writeBlock(StateWriter& out, Fill fill) {
  const std::size_t at = out.size();
  out.write(std::uint64_t{0});
  fill();
  const std::uint64_t size = out.size() - at - sizeof(std::uint64_t);
  std::memcpy(out.buffer().data() + at, &size, sizeof size);
}

// Format 7's checksum: FNV-1a's step (xor, multiply by its prime) on 8-byte words in four
// independent lanes, the bytes left over by FNV-1a itself, then the lanes and the size folded in.
// Each step is a bijection of its lane, so any one changed word changes the sum. Byte-wise FNV-1a
// (format 6) took 24 ms for the 21.4 MB state of 10,000 quadrotors on the 2-core development
// machine (49 ms while it was loaded), on the stepping thread whenever a recording saved a state;
// this takes 2.2 ms.
std::uint64_t stateChecksum(const std::byte* data, std::size_t size) {
  constexpr std::uint64_t kPrime = 1099511628211ull;
  std::uint64_t lane[4] = {kFnv1aBasis, kFnv1aBasis ^ 1, kFnv1aBasis ^ 2, kFnv1aBasis ^ 3};
  std::size_t i = 0;
  for (; i + 32 <= size; i += 32)
    for (int k = 0; k < 4; ++k) {
      std::uint64_t word = 0;
      std::memcpy(&word, data + i + 8 * k, 8);
      lane[k] = (lane[k] ^ word) * kPrime;
    }
  std::uint64_t h = fnv1a(data + i, size - i);
  for (const std::uint64_t l : lane) h = (h ^ l) * kPrime;
  return (h ^ size) * kPrime;
}

template <class Load>
void readBlock(StateReader& in, const std::string& what, Load load) {
  StateReader block = in.block(in.count(1), what);
  load(block);
  if (!block.done())
    throw StateError(what + " left " + std::to_string(block.remaining()) +
                     " bytes of its saved state unread (its saveState and loadState disagree)");
}

}  // namespace

std::uint64_t Environment::sceneFingerprint() const {
  // what a saved state must agree with: the timestep, the bodies, and each artifact's plugins;
  // fixed from start on (artifacts, plugins, ghosts and the scene's extensions are set up before)
  detail::World& w = *world_;
  if (w.fingerprint_known) return w.fingerprint;
  std::uint64_t h = fnv1a("ssx scene", kFnv1aBasis);
  auto mix = [&h](std::string_view s) { h = fnv1a(s, fnv1a("|", h)); };
  mix(std::to_string(settings_.timestep));
  // (not the engine: a state names its own, and restoring it switches to that one)
  for (const auto& a : world_->artifacts) {
    mix(a->name());
    // each dynamic root is one body, and each joined child (known before the engine is built)
    std::size_t bodies = 0;
    for (std::size_t r = 0; r < a->rootCount(); ++r) bodies += a->root(r).isStatic() ? 0 : 1;
    for (std::size_t k = 0; k < a->nodeCount(); ++k) bodies += a->nodeAt(k).joint().isBody() ? 1 : 0;
    mix(std::to_string(bodies));
  }
  for (const auto& p : world_->plugins)
    mix((p.index == 0 ? "driver " : "sensor ") + p.class_name + " " + std::to_string(p.period_steps) + " of " +
        std::to_string(p.artifact));
  for (const auto& e : extensions_)
    if (!e.observer) mix("extension " + e.name);  // (those attached while running are not in a state)
  for (const auto& g : ghosts_->list()) mix("ghost " + std::to_string(g.artifact));
  if (w.state != State::Setup) {
    w.fingerprint = h;
    w.fingerprint_known = true;
  }
  return h;
}

std::vector<std::byte> Environment::saveState() const {
  std::vector<std::byte> buffer;
  saveState(buffer);
  return buffer;
}

void Environment::saveState(std::vector<std::byte>& buffer) const {
  const detail::World& w = *world_;
  if (w.state != State::Running)
    throw Error("saveState: the environment is not running (start it, or it failed or stopped)");
  // written over what the buffer holds, grown to the last state's size first (no copy as it
  // grows: 21 MB at 10,000 quadrotors); values go in with a move each, not a call
  if (buffer.size() < w.state_size_hint) buffer.resize(w.state_size_hint);
  StateWriter out(buffer, kHeaderSize);
  out.write(w.steps);
  out.write(physics_->name());
  writeBlock(out, [&] { physics_->saveState(out); });
  out.write(static_cast<std::uint64_t>(w.states.size()));
  for (const auto& s : w.states) writeBody(out, s);
  for (std::size_t i = 0; i < w.states.size(); ++i) {
    out.write(w.previous_linear[i]);
    out.write(w.previous_angular[i]);
    out.write(w.wrenches[i].force);
    out.write(w.wrenches[i].torque);
  }
  // the joints' motor commands (none: nothing, as before there were joints)
  for (const auto& j : w.joints) {
    out.write(static_cast<std::uint8_t>(j.mode));
    out.write(j.target);
  }
  // the run-time joints (the engine's block has what makes them again)
  out.write(static_cast<std::uint64_t>(w.attachments.size()));
  for (const auto& x : w.attachments) {
    out.write(x.holder);
    out.write(x.held);
    out.write(static_cast<std::int32_t>(x.engine));
    out.write(static_cast<std::uint8_t>(x.kind));
  }
  detail::saveVariations(w, out);
  // the random streams, then each plugin's own state (driver first, then sensors, by artifact)
  for (const Random& r : w.randoms) r.save(out);
  for (const auto& a : w.artifact_data) {
    if (a.driver != nullptr) writeBlock(out, [&] { a.driver->saveState(out); });
    for (const auto& s : a.sensors) writeBlock(out, [&] { s.sensor->saveState(out); });
  }
  for (const auto& e : extensions_)
    if (!e.observer) writeBlock(out, [&] { e.extension->saveState(out); });
  if (!ghosts_->empty()) writeBlock(out, [&] { ghosts_->save(out); });
  std::uint64_t absent = 0;
  for (const auto& a : w.artifact_data) absent += a.absent ? 1 : 0;
  out.write(absent);
  for (std::size_t i = 0; i < w.artifact_data.size(); ++i)
    if (w.artifact_data[i].absent) out.write(static_cast<std::uint32_t>(i));

  out.finish();
  // the header, now that the payload is known
  const std::uint64_t payload = buffer.size() - kHeaderSize;
  const std::uint64_t checksum = stateChecksum(buffer.data() + kHeaderSize, payload);
  w.state_size_hint = buffer.size();
  const std::uint64_t fingerprint = sceneFingerprint();
  std::byte* h = buffer.data();
  std::memcpy(h, kMagic, 8);
  std::memcpy(h + 8, &kFormatVersion, 4);
  std::memset(h + 12, 0, 4);
  std::memcpy(h + 16, &fingerprint, 8);
  std::memcpy(h + 24, &payload, 8);
  std::memcpy(h + 32, &checksum, 8);
}

void Environment::checkState(std::span<const std::byte> state) const {
  // the header: what it is, and that it is whole and meant for this scene
  if (state.size() < kHeaderSize || std::memcmp(state.data(), kMagic, 8) != 0)
    throw StateError("restoreState: not an ssx saved state (" + std::to_string(state.size()) +
                     " bytes, no SSXSTATE header)");
  std::uint32_t version = 0;
  std::uint64_t fingerprint = 0, payload = 0, checksum = 0;
  std::memcpy(&version, state.data() + 8, 4);
  std::memcpy(&fingerprint, state.data() + 16, 8);
  std::memcpy(&payload, state.data() + 24, 8);
  std::memcpy(&checksum, state.data() + 32, 8);
  if (version < 6 || version > kFormatVersion)
    throw StateError("restoreState: saved state format " + std::to_string(version) + ", this ssx reads formats 6 to " +
                     std::to_string(kFormatVersion));
  if (payload != state.size() - kHeaderSize)
    throw StateError("restoreState: the saved state is " + std::to_string(state.size()) + " bytes, its header says " +
                     std::to_string(payload + kHeaderSize) + " (truncated?)");
  const std::byte* body = state.data() + kHeaderSize;
  if ((version == 6 ? fnv1a(body, payload) : stateChecksum(body, payload)) != checksum)
    throw StateError("restoreState: the saved state is corrupted (checksum mismatch)");
  if (fingerprint != sceneFingerprint())
    throw StateError("restoreState: the state was saved from a different scene (timestep, bodies, artifacts or "
                     "their plugins differ): load the scene it was saved from");
}

void Environment::reseed(std::uint64_t seed) {
  for (std::size_t i = 0; i < world_->plugins.size(); ++i)
    world_->randoms[i].reseed(deriveSeed(seed, world_->plugins[i].artifact, world_->plugins[i].index));
}

void Environment::restoreState(std::span<const std::byte> state) {
  checkState(state);  // before anything starts
  restoreChecked(state);
}

void Environment::restoreChecked(std::span<const std::byte> state) {
  if (world_->state == State::Setup) start();
  if (world_->state != State::Running) throw Error("restoreState: the environment failed or was stopped");

  // what can go wrong now is a plugin that reads back differently from how it saved: then the
  // state taken just before is put back, so a failed restore changes nothing. Bytes that were
  // restored here before without error (checked whole by checkState: the same checksum and size)
  // read back the same way again: no copy needed.
  detail::World& w = *world_;
  std::uint64_t checksum = 0;
  std::memcpy(&checksum, state.data() + 32, 8);
  if (checksum == w.restored_checksum && state.size() == w.restored_size) {
    applyState(state.subspan(kHeaderSize), formatOf(state));
    return;
  }
  const std::vector<std::byte> before = saveState();
  try {
    applyState(state.subspan(kHeaderSize), formatOf(state));
  } catch (const StateError&) {
    applyState(std::span<const std::byte>(before).subspan(kHeaderSize), kFormatVersion);
    throw;
  } catch (const std::exception& e) {
    applyState(std::span<const std::byte>(before).subspan(kHeaderSize), kFormatVersion);
    throw StateError(std::string("restoreState: ") + e.what());
  }
  w.restored_checksum = checksum;
  w.restored_size = state.size();
}

void Environment::applyState(std::span<const std::byte> payload, std::uint32_t format) {
  StateReader in(payload, "saved state");
  const auto steps = in.get<std::int64_t>();
  if (steps < 0) throw StateError("saved state: negative step count (corrupted)");
  // time is steps * timestep in 64-bit nanoseconds: the count must leave room to go on
  if (steps > static_cast<std::int64_t>(kMaxDurationSeconds * 1e9) / settings_.timestep)
    throw StateError("saved state: a step count of " + std::to_string(steps) +
                     " is beyond the longest run (1e9 s of simulated time; corrupted?)");
  std::string engine;
  in.read(engine);
  const auto names = physicEngineNames();
  if (std::find(names.begin(), names.end(), engine) == names.end())
    throw StateError("saved state: saved by physics engine '" + engine + "', which this build of ssx does not have");
  if (engine != physics_->name()) exchangePhysics(engine);
  readBlock(in, "the physics engine's state", [&](StateReader& block) { physics_->restoreState(block); });
  const std::size_t bodies = in.count(1);
  detail::World& w = *world_;
  if (bodies != w.states.size())
    throw StateError("saved state: " + std::to_string(bodies) + " bodies, this world " +
                     std::to_string(w.states.size()));
  for (auto& s : w.states) readBody(in, s);
  for (std::size_t i = 0; i < w.states.size(); ++i) {
    in.read(w.previous_linear[i]);
    in.read(w.previous_angular[i]);
    in.read(w.wrenches[i].force);
    in.read(w.wrenches[i].torque);
    // a command a driver could have given (the engine applies it in the next step)
    if (!detail::finite(w.wrenches[i]) || !detail::withinLimit(w.wrenches[i], w.wrench_limits[i]))
      throw StateError("saved state: the command held for body " + std::to_string(i) +
                       " is not finite or beyond the speed guards (corrupted)");
  }
  for (auto& j : w.joints) {
    const auto mode = in.get<std::uint8_t>();
    in.read(j.target);
    if (mode > static_cast<std::uint8_t>(detail::JointData::Mode::Position) || !std::isfinite(j.target))
      throw StateError("saved state: a joint's motor command is not one a driver could give (corrupted)");
    j.mode = static_cast<detail::JointData::Mode>(mode);
  }
  detail::loadAttachments(w, in);
  detail::loadVariations(w, in);
  for (Random& r : w.randoms) r.load(in);
  for (std::size_t i = 0; i < w.artifacts.size(); ++i) {
    const std::string of = " of artifact '" + w.artifacts[i]->name() + "'";
    detail::ArtifactData& a = w.artifact_data[i];
    if (a.driver != nullptr)
      readBlock(in, "driver '" + a.driver->className() + "'" + of, [&](StateReader& b) { a.driver->loadState(b); });
    for (auto& s : a.sensors)
      readBlock(in, "sensor '" + s.sensor->className() + "'" + of, [&](StateReader& b) { s.sensor->loadState(b); });
  }
  for (auto& e : extensions_)
    if (!e.observer)
      readBlock(in, "extension '" + e.name + "'", [&](StateReader& block) { e.extension->loadState(block); });
  if (!ghosts_->empty()) readBlock(in, "the ghosts' poses", [&](StateReader& block) { ghosts_->load(block, w); });
  // the artifacts out of the world (format 8 on; before, every artifact was in), checked whole first
  std::vector<std::uint8_t> absent(w.artifacts.size(), 0);
  if (format >= 8) {
    const std::size_t count = in.count(4);
    for (std::size_t k = 0; k < count; ++k) {
      const auto i = in.get<std::uint32_t>();
      if (i >= w.artifacts.size() || absent[i] != 0 || w.artifacts[i]->rootCount() == 0 ||
          w.artifacts[i]->root().isStatic() || isGhost(*w.artifacts[i]))
        throw StateError("saved state: artifact " + std::to_string(i) + " cannot be out of the world here (corrupted)");
      absent[i] = 1;
    }
  }
  if (!in.done()) throw StateError("saved state: " + std::to_string(in.remaining()) + " bytes left over (corrupted)");
  std::vector<std::uint8_t> was_absent(w.artifacts.size());
  for (std::size_t i = 0; i < w.artifacts.size(); ++i) {
    was_absent[i] = w.artifact_data[i].absent ? 1 : 0;
    w.artifact_data[i].absent = absent[i] != 0;
  }
  detail::applyPresence(w, *physics_, was_absent);
  if (neighbors_->enabled() && was_absent != absent) neighbors_->markMembersChanged(w);
  w.steps = steps;
  w.current_step = steps;
  physics_->recordContacts(w.record_contacts);  // (the last step's contacts are another run's)
  cameras_->invalidate();
  if (neighbors_->enabled()) neighbors_->markStale(w);
  rays_stale_ = true;
}

}  // namespace ssx
