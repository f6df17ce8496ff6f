// A robot that starts inside another robot, an obstacle or the ground: an error when the scene is
// built (and so in `ssx validate`), with both names and the scene lines, unless a placement
// allows it. Without it the engine would push the two apart at the first step, meters per second
// from nowhere, and the run would report a crash with no cause.

#include "scene/builder.hpp"

#include "engines/shape_overlaps.hpp"

#include <cstdio>
#include <map>

namespace ssx::detail {

namespace {

// what resting on a surface may sink into it: ODE's contact surface layer, far below any
// placement mistake
constexpr double kStartOverlapTolerance = 1e-3;  // m

// messages per pair of placements (a swarm laid on the ground would give one per member)
constexpr int kReportsPerPair = 3;

std::string millimetres(double metres) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f mm", metres * 1e3);
  return text;
}

std::string point(const Vec3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.3f, %.3f, %.3f)", p.x(), p.y(), p.z());
  return text;
}

}  // namespace

void SceneBuilder::checkStartOverlaps(const Environment& env, const SceneModel& model,
                                     const std::vector<std::size_t>& placement_of) {
  std::vector<PosedShape> shapes;
  bool any_dynamic = false;
  for (std::size_t i = 0; i < env.artifactCount(); ++i) {
    const Artifact& a = env.artifact(i);
    // moved by a real robot's poses, or out of the world until spawned: nothing was placed
    if (env.isGhost(a) || !a.present()) continue;
    for (std::size_t n = 0; n < a.nodeCount(); ++n) {
      const PhysicNode& node = a.nodeAt(n);
      const Pose pose = node.pose();
      for (const Shape& s : node.spec().shapes) {
        shapes.push_back(PosedShape{&s, pose * s.pose, i, node.isStatic()});
        any_dynamic = any_dynamic || !node.isStatic();
      }
    }
  }
  if (!any_dynamic) return;
  std::map<std::pair<std::size_t, std::size_t>, int> reported;  // by pair of placements

  for (const ShapeOverlap& o : findShapeOverlaps(shapes, kStartOverlapTolerance)) {
    const std::size_t ia = shapes[o.first].owner;
    const std::size_t ib = shapes[o.second].owner;
    const PlacementModel& pa = model.placements.at(placement_of.at(ia));
    const PlacementModel& pb = model.placements.at(placement_of.at(ib));
    if (pa.allow_overlap || pb.allow_overlap) continue;
    // reported at the robot's line (the later one when both move); the other is named with its line
    const bool a_moves = !shapes[o.first].is_static;
    const bool b_moves = !shapes[o.second].is_static;
    const bool at_b = b_moves && (!a_moves || ib > ia);
    const std::size_t robot = at_b ? ib : ia;
    const std::size_t other = at_b ? ia : ib;
    const PlacementModel& rp = at_b ? pb : pa;
    const PlacementModel& op = at_b ? pa : pb;
    const std::size_t rk = at_b ? placement_of[ib] : placement_of[ia];
    const std::size_t ok = at_b ? placement_of[ia] : placement_of[ib];
    int& count = reported[{rk, ok}];
    if (++count > kReportsPerPair) continue;
    log_.stage = placementStage(rk);
    const std::string& other_name = env.artifact(other).name();
    const bool ground = op.kind == PlacementModel::Kind::Ground;
    std::string message = "'" + env.artifact(robot).name() + "' starts " + millimetres(o.depth) + " inside '" +
                          other_name + "' (" + op.where.str() + ") at " + point(o.point) + ": ";
    message += ground ? "raise it so that it rests on the ground" : "move them apart";
    message += ", or set allow_overlap=\"true\" on the <" +
               std::string(rp.kind == PlacementModel::Kind::Swarm ? "swarm" : "artifact") + "> if it is meant";
    error(rp.where, message);
  }
  // how many more, per pair of placements that said more than kReportsPerPair
  for (const auto& [pair, count] : reported) {
    if (count <= kReportsPerPair) continue;
    const PlacementModel& rp = model.placements.at(pair.first);
    log_.stage = placementStage(pair.first);
    const PlacementModel& op = model.placements.at(pair.second);
    const std::string kind = rp.kind == PlacementModel::Kind::Swarm ? "<swarm>" : "<artifact>";
    const std::string more = "... and " + std::to_string(count - kReportsPerPair) + " more overlaps ";
    if (pair.first == pair.second)
      error(rp.where, more + "between members of this " + kind);
    else if (op.kind == PlacementModel::Kind::Swarm)
      error(rp.where, more + "between this " + kind + " and the members of the <swarm> at " + op.where.str());
    else
      error(rp.where, more + "between this " + kind + " and '" + op.name + "'");
  }
}

}  // namespace ssx::detail
