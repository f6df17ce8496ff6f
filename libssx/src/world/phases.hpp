#pragma once
// The phases of a step as functions over the world state (environment.hpp documents the order).
// Environment::start and Environment::step call them; bodies.cpp and step_phases.cpp define them.

#include "world/world.hpp"

#include <ssx/environment.hpp>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace ssx::detail {

/// Flattens every artifact's node trees into rigid bodies of `engine` (static roots become static
/// shapes, listed in `static_shapes`), fills the nodes' body indices and the body arrays. With
/// `static_shapes` null, makes the same bodies and joints again in another engine (switching
/// engines): the body arrays and the snapshot are left as they are.
void buildBodies(World& world, PhysicEngine& engine, std::vector<Environment::StaticShape>* static_shapes);
/// Takes the bodies of artifacts out of the engine's world, or puts them back, where their
/// `absent` flag differs from `was_absent` (per artifact; empty: all were in, as in an engine just
/// built; presence.cpp).
void applyPresence(World& world, PhysicEngine& engine, std::span<const std::uint8_t> was_absent);
/// Makes the engine's joints from the node trees (the end of buildBodies; joints.cpp).
void buildJoints(World& world, PhysicEngine& engine);
/// Before a physics step: sets the motors' velocities; returns the wrenches to apply (the drivers',
/// or a copy with the joints' damping added).
const Wrench* applyJoints(World& world, PhysicEngine& engine);
/// After the drivers phase: carries out the run-time joints the drivers asked for (attachments.cpp),
/// artifact by artifact.
void applyAttachRequests(World& world, PhysicEngine& engine);
/// Reads the run-time joints saveState wrote (after the engine restored its joints);
/// throws StateError for what does not fit the world.
void loadAttachments(World& world, StateReader& in);
/// Makes the run-time joints again in another engine (switching engines), where the bodies are now.
void reattach(World& world, PhysicEngine& engine);
/// Writes the varied constants (World::varied) into a saved state; variations.cpp.
void saveVariations(const World& world, StateWriter& out);
/// Reads them back and sets every constant to the state's value (the others to their neutral
/// ones); throws StateError for an entry that fits no variable of the world.
void loadVariations(World& world, StateReader& in);
/// Sets the bodies' mass scales World::varied holds on `engine` (one just made: switching engines).
void applyMassScales(const World& world, PhysicEngine& engine);
/// A hinge's angle or slider's displacement from the snapshot (0 before start).
double jointPosition(const World& world, const JointData& joint);
/// A hinge's or slider's rate from the snapshot (0 before start).
double jointVelocity(const World& world, const JointData& joint);
/// Reads the engine's states into the snapshot, with accelerations (not on the first), and checks
/// them; a diverged body fails the world and throws StepError.
void publishSnapshot(World& world, const PhysicEngine& engine, bool first);
/// Clears the command buffers of artifacts without a driver (nothing holds their forces).
void clearUndrivenCommands(World& world);
/// The sensors and drivers phases over artifacts [begin, end); failures go to world.errors.
void runSensors(World& world, std::size_t begin, std::size_t end);
void runDrivers(World& world, std::size_t begin, std::size_t end);

}  // namespace ssx::detail
