#pragma once
// What both engines do alike with their joints (each engine's Joint has `spec`, `velocity`,
// `max_effort` and `removed`):
// - which bodies are joined to each other, directly or through others (contacts between them are
//   skipped, they are solved together): labels recomputed whole whenever joints come or go
//   (union-find, linear in bodies and joints), so that letting go of a joint splits a chain again;
// - a run-time joint's slot (the first one a removed joint left);
// - the run-time joints' records in the engine's saved state, with what each engine needs to make
//   one again to the bit (`extra`: ODE's body states when made, Bullet's frames).

#include <ssx/error.hpp>
#include <ssx/physic_engine.hpp>
#include <ssx/state.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

namespace ssx::detail {

// label[i] becomes the lowest body joined to i by a joint in place (i itself when none)
template <class Joint>
void labelArticulations(std::vector<int>& label, std::size_t bodies, const std::vector<Joint>& joints) {
  label.resize(bodies);
  std::iota(label.begin(), label.end(), 0);
  auto find = [&label](int x) {
    while (label[static_cast<std::size_t>(x)] != x) {
      const int up = label[static_cast<std::size_t>(label[static_cast<std::size_t>(x)])];
      label[static_cast<std::size_t>(x)] = up;
      x = up;
    }
    return x;
  };
  for (const Joint& j : joints) {
    if (j.removed || j.spec.parent < 0) continue;  // (a joint to the static world joins nothing)
    const int ra = find(j.spec.child), rb = find(j.spec.parent);
    // the lower root stays the root: a set's root is its lowest body
    if (ra != rb) label[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
  }
  for (std::size_t i = 0; i < label.size(); ++i) label[i] = find(static_cast<int>(i));
}

// hangs[i]: the static group that body i's articulation is joined to (EngineJoint::static_group of
// a joint to the static world in it; the first such joint's), else -1; `label` from
// labelArticulations. Contacts between the two are skipped, as between joined bodies.
template <class Joint>
void labelStaticParents(std::vector<int>& hangs, const std::vector<int>& label, const std::vector<Joint>& joints) {
  hangs.assign(label.size(), -1);
  std::vector<int> of_root(label.size(), -1);
  for (const Joint& j : joints)
    if (!j.removed && j.spec.parent < 0 && j.spec.static_group >= 0) {
      int& g = of_root[static_cast<std::size_t>(label[static_cast<std::size_t>(j.spec.child)])];
      if (g < 0) g = j.spec.static_group;
    }
  for (std::size_t i = 0; i < label.size(); ++i) hangs[i] = of_root[static_cast<std::size_t>(label[i])];
}

// puts a new joint in the first slot a removed run-time joint left (at or after `first`, once
// sealed), else at the end; returns its index
template <class Joint>
std::size_t placeJoint(std::vector<Joint>& joints, Joint&& joint, std::size_t first, bool sealed) {
  for (std::size_t k = first; sealed && k < joints.size(); ++k)
    if (joints[k].removed) {
      joints[k] = std::move(joint);
      return k;
    }
  joints.push_back(std::move(joint));
  return joints.size() - 1;
}

// joints[first, end): removed ones as a flag, the others with their spec, motor and `extra(out, j)`
template <class Joint, class Extra>
void saveRunTimeJoints(StateWriter& out, const std::vector<Joint>& joints, std::size_t first, Extra&& extra) {
  out.write(static_cast<std::uint64_t>(joints.size() - first));
  for (std::size_t k = first; k < joints.size(); ++k) {
    const Joint& j = joints[k];
    out.write(static_cast<std::uint8_t>(j.removed ? 1 : 0));
    if (j.removed) continue;
    out.write(static_cast<std::uint8_t>(j.spec.kind));
    out.write(static_cast<std::int32_t>(j.spec.parent));
    out.write(static_cast<std::int32_t>(j.spec.child));
    out.write(j.spec.frame);
    out.write(j.spec.lower);
    out.write(j.spec.upper);
    out.write(j.velocity);
    out.write(j.max_effort);
    extra(out, j);
  }
}

// reads what saveRunTimeJoints wrote, `extra(in, j)` after each joint's spec (it returns whether
// what it read is finite); throws StateError, naming `engine`, for a record that does not fit a
// world of `bodies` bodies. Nothing is changed.
template <class Joint, class Extra>
std::vector<Joint> loadRunTimeJoints(StateReader& in, int bodies, const char* engine, Extra&& extra) {
  std::vector<Joint> out(in.count(1));
  for (Joint& j : out) {
    if (in.get<std::uint8_t>() != 0) {
      j.removed = true;
      continue;
    }
    const auto kind = in.get<std::uint8_t>();
    j.spec.parent = in.get<std::int32_t>();
    j.spec.child = in.get<std::int32_t>();
    in.read(j.spec.frame);
    in.read(j.spec.lower);
    in.read(j.spec.upper);
    in.read(j.velocity);
    in.read(j.max_effort);
    const bool finite = extra(in, j);
    if (!finite || kind > static_cast<std::uint8_t>(JointSpec::Kind::Fixed) ||
        kind == static_cast<std::uint8_t>(JointSpec::Kind::Rigid) || j.spec.child < 0 || j.spec.child >= bodies ||
        j.spec.parent < -1 || j.spec.parent >= bodies || j.spec.parent == j.spec.child || !std::isfinite(j.velocity) ||
        !(j.max_effort >= 0) || !std::isfinite(j.max_effort) || !j.spec.frame.position.allFinite() ||
        !j.spec.frame.orientation.coeffs().allFinite())
      throw StateError(std::string(engine) + ": a run-time joint in the saved state does not fit this world (corrupted)");
    j.spec.kind = static_cast<JointSpec::Kind>(kind);
  }
  return out;
}

}  // namespace ssx::detail
