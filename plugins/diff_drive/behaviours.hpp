#pragma once
// The diff_drive's built-in behaviours (ground_controller.hpp), chosen by `controller`:
//
// "diffusion": the robot wanders and avoids what its first proximity sensor sees, as ARGoS's
// foot-bot diffusion example does: the readings summed as vectors along their rays; when their
// direction is within `diffusion_angle` of straight ahead and their length below
// `diffusion_delta`, both wheels at `cruise_speed`; otherwise it turns away on the spot's far wheel.
//
// "beeclust": BEECLUST (Schmickl et al.), cue-based aggregation. It wanders as in diffusion; when
// its range-and-bearing board hears a robot nearer than `meet_range`, it stops and waits
// `wait_max * c^2 / (c^2 + cue_theta)` s, c the darkness its first ground sensor reads (1 - grey),
// then turns on the spot by a random angle and wanders again. Robots meeting on a dark spot wait
// long there: they gather on it.
//
// "foraging": central-place foraging. Items broadcast `item_code` as the first byte of their
// range-and-bearing payload (range_and_bearing `data`); the nest is floor its ground sensor reads
// at least `nest_level` on. The robot wanders (diffusion) until it hears an item that nobody holds,
// steers to it, and within `grab_range` holds it by a fixed joint (PhysicNode::attach); then it
// heads home by path integration (the mean of where its odometry had it in the nest), lets go once
// in the nest, turns away and goes back to where it found the item (site fidelity, as foraging
// ants do), searching from there. Obstacles seen on the way make it diffuse.
//
// "twist": drives at a constant `twist` (forward speed and yaw rate) from the start: a circle, or a
// straight line (a scripted ground robot for air-ground scenes).
#include "ground_controller.hpp"

#include <memory>

namespace ssx::ground {

inline constexpr ssx_plugin_param kBehaviourParameters[] = {
    param::choice("controller", "none", "none diffusion beeclust foraging twist",
                  "none: commands from outside; diffusion: wander, turning away from what the proximity sensor "
                  "sees; beeclust: wander, and wait where robots meet, longer on darker floor; foraging: carry "
                  "items heard over range-and-bearing to the nest; twist: drive at a constant twist"),
    param::vec3("twist", "0 0 0", "", param::any(),
                "twist: 'V W 0', forward speed (m/s) and yaw rate (rad/s) from the start"),
    param::real("cruise_speed", "0", "rad/s", param::nonNegative(),
                "diffusion: wheel speed going straight (0: max_wheel_speed)"),
    param::real("diffusion_delta", "0.1", "", param::positive(),
                "diffusion: obstacle vector length that makes it turn"),
    param::real("diffusion_angle", "5", "deg", param::between(0, 180),
                "diffusion: obstacles within this of straight ahead make it turn"),
    param::real("meet_range", "0.1", "m", param::positive(), "beeclust: a robot heard nearer than this is met"),
    param::real("wait_max", "60", "s", param::nonNegative(), "beeclust: the longest wait, on the darkest floor"),
    param::real("cue_theta", "0.1", "", param::positive(),
                "beeclust: the darkness squared at which it waits half as long"),
    param::integer("item_code", "1", param::between(1, 255), "foraging: the first payload byte items send"),
    param::real("grab_range", "0.07", "m", param::positive(), "foraging: an item heard nearer than this is taken"),
    param::real("nest_level", "0.9", "", param::between(0, 1),
                "foraging: the grey level (at least) of the nest's floor"),
};

/// The sensors the chosen behaviour needs, on artifact `a`; throws ConfigError at `controller`.
void validateBehaviour(const Descriptor& params, const Artifact& a);

/// The behaviour `controller` names for artifact `a`, driving `drive` (configured); null for "none".
std::unique_ptr<GroundController> makeBehaviour(const Descriptor& params, const Artifact& a, const DriveModel& drive);

}  // namespace ssx::ground
