// The world's bodies: node trees flattened into rigid bodies at start, and the snapshot published
// after each physics step (poses, velocities, accelerations, checked for divergence).
#include "phases.hpp"
#include "state_checks.hpp"

#include <ssx/environment.hpp>
#include <ssx/hash.hpp>

#include <cstring>

namespace ssx {

namespace detail {

void buildBodies(World& world, PhysicEngine& engine, std::vector<Environment::StaticShape>& static_shapes) {
  // flatten each node tree into one rigid body whose frame is the tree's centre-of-mass frame
  for (auto& artifact : world.artifacts) {
    ArtifactData& data = world.data(*artifact);
    data.body_begin = static_cast<int>(engine.bodyCount());
    for (std::size_t r = 0; r < artifact->rootCount(); ++r) {
      const PhysicNode& root = artifact->root(r);
      const PhysicNodeSpec& spec = root.spec();
      const NodeSetup& root_data = world.node_setup[root.nodeIndex()];
      std::vector<Shape> shapes;
      std::vector<std::size_t> tree;  // the root and its descendants, in order
      std::vector<const PhysicNodeSpec*> specs;
      // (each node's pose in its body was set when the tree was added: Artifact::addPhysicRoot)
      for (std::size_t k = 0; k < artifact->nodeCount(); ++k) {
        const PhysicNode& n = artifact->nodeAt(k);
        const PhysicNode* top = &n;
        while (top->parent() != nullptr) top = top->parent();
        if (top != &root) continue;
        tree.push_back(n.nodeIndex());
        specs.push_back(&n.spec());
      }
      if (spec.is_static) {
        for (std::size_t k = 0; k < tree.size(); ++k) {
          const NodeData& n = world.nodes[tree[k]];
          for (Shape s : specs[k]->shapes) {
            s.pose = n.pose_in_body * s.pose;
            shapes.push_back(s);
            static_shapes.push_back({s, root_data.pose * s.pose, artifact->index()});
          }
        }
        engine.addStatic(shapes, root_data.pose);
        continue;
      }
      const MassProperties mass = combinedMass(spec);
      const Pose& root_in_body = world.nodes[root.nodeIndex()].pose_in_body;
      for (std::size_t k = 0; k < tree.size(); ++k) {
        const NodeData& n = world.nodes[tree[k]];
        for (Shape s : specs[k]->shapes) {
          s.pose = n.pose_in_body * s.pose;
          shapes.push_back(s);
        }
      }
      BodyState initial;
      initial.pose = root_data.pose * root_in_body.inverse();
      initial.angular_velocity = root_data.initial_angular;
      initial.linear_velocity = root_data.initial_linear +
                                root_data.initial_angular.cross(initial.pose.position - root_data.pose.position);
      const int body = engine.addBody(mass, shapes, initial);
      for (std::size_t k : tree) world.nodes[k].body = body;
      world.body_owner.push_back(static_cast<std::uint32_t>(artifact->index()));
      world.wrench_limits.push_back(wrenchLimit(mass, world.settings.physics, world.settings.timestep));
    }
    data.body_end = static_cast<int>(engine.bodyCount());
  }
  world.states.assign(engine.bodyCount(), BodyState{});
  world.previous_linear.assign(world.states.size(), Vec3::Zero());
  world.previous_angular.assign(world.states.size(), Vec3::Zero());
  world.wrenches.assign(world.states.size(), Wrench{});
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
