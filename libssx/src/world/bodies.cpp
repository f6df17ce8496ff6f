// The world's bodies: node trees flattened into rigid bodies at start, and the snapshot published
// after each physics step (poses, velocities, accelerations, checked for divergence).
#include "world/phases.hpp"
#include "engines/state_checks.hpp"

#include <ssx/environment.hpp>
#include <ssx/hash.hpp>

#include <cstring>

namespace ssx {

namespace detail {

void buildBodies(World& world, PhysicEngine& engine, std::vector<Environment::StaticShape>* static_shapes) {
  // each node tree becomes one rigid body whose frame is its centre-of-mass frame, and one more for
  // each joined child (with its rigid descendants)
  std::vector<std::size_t> head;  // per node of the artifact: the node its body begins at
  for (auto& artifact : world.artifacts) {
    ArtifactData& data = world.data(*artifact);
    data.body_begin = static_cast<int>(engine.bodyCount());
    const std::size_t count = artifact->nodeCount();
    if (count == 0) {
      data.body_end = data.body_begin;
      continue;
    }
    const std::size_t offset = artifact->nodeAt(0).nodeIndex();  // (an artifact's nodes are consecutive)
    head.assign(count, 0);
    for (std::size_t k = 0; k < count; ++k) {
      const PhysicNode& n = artifact->nodeAt(k);
      head[k] = n.parent() == nullptr || n.spec().joint.isBody() ? k : head[n.parent()->nodeIndex() - offset];
    }
    for (std::size_t h = 0; h < count; ++h) {
      if (head[h] != h) continue;
      const PhysicNode& top = artifact->nodeAt(h);
      // its first velocity: set on the node it begins at, else the tree's root's (the tree moving as one)
      const PhysicNode* root = &top;
      while (root->parent() != nullptr) root = root->parent();
      const NodeSetup& top_data = world.node_setup[top.nodeIndex()];
      const NodeSetup& root_data = top_data.velocity_set ? top_data : world.node_setup[root->nodeIndex()];
      // (each node's pose in its body was set when the tree was added: Artifact::addPhysicRoot)
      std::vector<Shape> shapes;
      for (std::size_t k = h; k < count; ++k) {
        if (head[k] != h) continue;
        const NodeData& n = world.nodes[offset + k];
        for (Shape s : artifact->nodeAt(k).spec().shapes) {
          s.pose = n.pose_in_body * s.pose;
          shapes.push_back(s);
          if (n.is_static && static_shapes != nullptr) static_shapes->push_back({s, top_data.pose * s.pose, artifact->index()});
        }
      }
      if (top.isStatic()) {
        const int group = engine.addStatic(shapes, top_data.pose);
        if (static_shapes != nullptr) world.static_group_owner.push_back(static_cast<std::uint32_t>(artifact->index()));
        for (std::size_t k = h; k < count; ++k)
          if (head[k] == h) world.nodes[offset + k].static_group = group;
        continue;
      }
      const MassProperties mass = bodyMass(top.spec());
      BodyState initial;
      initial.pose = top_data.pose * world.nodes[top.nodeIndex()].pose_in_body.inverse();
      initial.angular_velocity = root_data.initial_angular;
      initial.linear_velocity = root_data.initial_linear +
                                root_data.initial_angular.cross(initial.pose.position - root_data.pose.position);
      const int body = engine.addBody(mass, shapes, initial);
      for (std::size_t k = h; k < count; ++k)
        if (head[k] == h) world.nodes[offset + k].body = body;
      if (static_shapes == nullptr) continue;  // (made again: the arrays are as they were)
      world.body_owner.push_back(static_cast<std::uint32_t>(artifact->index()));
      world.wrench_limits.push_back(wrenchLimit(mass, world.settings.physics, world.settings.timestep));
    }
    data.body_end = static_cast<int>(engine.bodyCount());
  }
  if (static_shapes != nullptr) {
    world.states.assign(engine.bodyCount(), BodyState{});
    world.previous_linear.assign(world.states.size(), Vec3::Zero());
    world.previous_angular.assign(world.states.size(), Vec3::Zero());
    world.wrenches.assign(world.states.size(), Wrench{});
  }
  buildJoints(world, engine);
}

void publishSnapshot(World& world, const PhysicEngine& engine, bool first) {
  std::vector<BodyState>& states = world.states;
  if (!first) {
    for (std::size_t i = 0; i < states.size(); ++i) {
      world.previous_linear[i] = states[i].linear_velocity;
      world.previous_angular[i] = states[i].angular_velocity;
    }
  }
  engine.readStates(states);
  const PhysicsSettings& ps = world.settings.physics;
  const double inv_dt = 1.0 / toSeconds(world.settings.timestep);
  const double max_v2 = ps.max_linear_speed * ps.max_linear_speed;
  const double max_w2 = ps.max_angular_speed * ps.max_angular_speed;
  for (std::size_t i = 0; i < states.size(); ++i) {
    BodyState& s = states[i];
    if (!finite(s) || s.linear_velocity.squaredNorm() > max_v2 || s.angular_velocity.squaredNorm() > max_w2) {
      world.state = Environment::State::Failed;
      throw StepError(world.artifacts[world.body_owner[i]]->name(), "physics", world.steps - 1,
                      "the simulation diverged: the state is NaN, infinite or faster than max_linear_speed / "
                      "max_angular_speed (an absurd force, or a timestep too large for the contacts)");
    }
    if (first) continue;
    s.linear_acceleration = (s.linear_velocity - world.previous_linear[i]) * inv_dt;
    s.angular_acceleration = (s.angular_velocity - world.previous_angular[i]) * inv_dt;
  }
}

}  // namespace detail

std::uint64_t Environment::stateHash() const {
  // FNV-1a over the raw bits of every pose and velocity, then the step count
  std::uint64_t h = kFnv1aBasis;
  auto mix = [&h](const double* p, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) {
      std::uint64_t bits;
      std::memcpy(&bits, p + i, sizeof bits);
      h = fnv1a(bits, h);
    }
  };
  for (const auto& s : world_->states) {
    mix(s.pose.position.data(), 3);
    mix(s.pose.orientation.coeffs().data(), 4);
    mix(s.linear_velocity.data(), 3);
    mix(s.angular_velocity.data(), 3);
  }
  const double steps = static_cast<double>(world_->steps);
  mix(&steps, 1);
  return h;
}

}  // namespace ssx
