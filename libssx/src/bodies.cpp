// The world's bodies: node trees flattened into rigid bodies at start, and the snapshot published
// after each physics step (poses, velocities, accelerations, checked for divergence).
#include "state_checks.hpp"

#include <ssx/environment.hpp>

#include <cstring>

namespace ssx {

void Environment::buildBodies() {
  // flatten each node tree into one rigid body whose frame is the tree's centre-of-mass frame
  for (auto& artifact : artifacts_) {
    artifact->body_begin_ = static_cast<int>(physics_->bodyCount());
    for (PhysicNode* root : artifact->roots_) {
      const PhysicNodeSpec& spec = root->spec();
      std::vector<Shape> shapes;
      std::vector<PhysicNode*> tree;  // the root and its descendants, in order
      for (auto& n : artifact->nodes_) {
        const PhysicNode* r = n.get();
        while (r->parent_ != nullptr) r = r->parent_;
        if (r == root) tree.push_back(n.get());
      }
      if (spec.is_static) {
        for (PhysicNode* n : tree) {
          n->pose_in_body_ = root->setup_pose_.inverse() * n->setup_pose_;
          for (Shape s : n->spec().shapes) {
            s.pose = n->pose_in_body_ * s.pose;
            shapes.push_back(s);
            static_shapes_.push_back({s, root->setup_pose_ * s.pose, artifact->index()});
          }
        }
        physics_->addStatic(shapes, root->setup_pose_);
        continue;
      }
      const MassProperties mass = combinedMass(spec);
      const Pose root_in_body{-mass.center_of_mass, Quat::Identity()};
      for (PhysicNode* n : tree) {
        n->pose_in_body_ = root_in_body * (root->setup_pose_.inverse() * n->setup_pose_);
        for (Shape s : n->spec().shapes) {
          s.pose = n->pose_in_body_ * s.pose;
          shapes.push_back(s);
        }
      }
      BodyState initial;
      initial.pose = root->setup_pose_ * root_in_body.inverse();
      initial.angular_velocity = root->initial_angular_;
      initial.linear_velocity =
          root->initial_linear_ + root->initial_angular_.cross(initial.pose.position - root->setup_pose_.position);
      const int body = physics_->addBody(mass, shapes, initial);
      for (PhysicNode* n : tree) n->body_ = body;
      body_owner_.push_back(artifact.get());
    }
    artifact->body_end_ = static_cast<int>(physics_->bodyCount());
  }
  states_.assign(physics_->bodyCount(), BodyState{});
  previous_linear_.assign(states_.size(), Vec3::Zero());
  previous_angular_.assign(states_.size(), Vec3::Zero());
  wrenches_.assign(states_.size(), Wrench{});
}

void Environment::publishSnapshot(bool first) {
  if (!first) {
    for (std::size_t i = 0; i < states_.size(); ++i) {
      previous_linear_[i] = states_[i].linear_velocity;
      previous_angular_[i] = states_[i].angular_velocity;
    }
  }
  physics_->readStates(states_);
  const double inv_dt = 1.0 / toSeconds(settings_.timestep);
  const double max_v2 = settings_.physics.max_linear_speed * settings_.physics.max_linear_speed;
  const double max_w2 = settings_.physics.max_angular_speed * settings_.physics.max_angular_speed;
  for (std::size_t i = 0; i < states_.size(); ++i) {
    BodyState& s = states_[i];
    if (!detail::finite(s) || s.linear_velocity.squaredNorm() > max_v2 || s.angular_velocity.squaredNorm() > max_w2) {
      fail();
      throw StepError(body_owner_[i]->name(), "physics", steps_ - 1,
                      "the simulation diverged: the state is NaN, infinite or faster than max_linear_speed / "
                      "max_angular_speed (an absurd force, or a timestep too large for the contacts)");
    }
    if (first) continue;
    s.linear_acceleration = (s.linear_velocity - previous_linear_[i]) * inv_dt;
    s.angular_acceleration = (s.angular_velocity - previous_angular_[i]) * inv_dt;
  }
}

std::uint64_t Environment::stateHash() const {
  // FNV-1a over the raw bits of every pose and velocity, then the step count
  std::uint64_t h = 0xcbf29ce484222325ULL;
  auto mix = [&h](const double* p, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) {
      std::uint64_t bits;
      std::memcpy(&bits, p + i, sizeof bits);
      for (int k = 0; k < 8; ++k) {
        h ^= (bits >> (8 * k)) & 0xffU;
        h *= 0x100000001b3ULL;
      }
    }
  };
  for (const auto& s : states_) {
    mix(s.pose.position.data(), 3);
    mix(s.pose.orientation.coeffs().data(), 4);
    mix(s.linear_velocity.data(), 3);
    mix(s.angular_velocity.data(), 3);
  }
  const double steps = static_cast<double>(steps_);
  mix(&steps, 1);
  return h;
}

}  // namespace ssx
