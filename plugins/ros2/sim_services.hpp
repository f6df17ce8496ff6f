#pragma once
// The ROS 2 standard simulation services (ros-simulation/simulation_interfaces 1.x) over Cyclone
// DDS, as rmw_cyclonedds_cpp serves a ROS 2 service: requests on rq/<name>Request, replies on
// rr/<name>Reply, each led by the request header (the client's id and the call's number, repeated
// in the reply so that the client knows its answer).
//
// A call is taken on Cyclone's receive thread and answered on the stepping thread between two
// steps (RunControl::post): it reads or moves a world that is not stepping, and a call never waits
// inside a step. StepSimulation is answered once its steps are taken (afterStep). Served:
// /get_simulator_features, /get_simulation_state, /set_simulation_state (playing, paused, stopped:
// paused at the start state, quitting: the run ends), /step_simulation (while paused),
// /reset_simulation (back to the state the run started from), /get_entities (by name, a POSIX
// extended regular expression, and category), /get_entity_state, /set_entity_state (a robot moved
// whole: every body of its artifact), /spawn_entity and /delete_entity (refused: ssx builds its
// world before the run starts; FEATURE_UNSUPPORTED says so).
#include <ssx/environment.hpp>

#include <dds/dds.h>

#include <functional>
#include <memory>
#include <string>

namespace ssx::ros2 {

class SimulationServices {
 public:
  /// Serves the services under `prefix` ("" : /get_entities, ...) on `participant` for `env`.
  /// `restarted` is called on the stepping thread after the world was put back to its start
  /// (a reset, a stop): what keeps time of its own starts again. Throws std::runtime_error when
  /// DDS refuses a topic.
  SimulationServices(dds_entity_t participant, Environment& env, std::string prefix, std::function<void()> restarted);
  /// Stops serving (calls that arrive or wait after this are not answered).
  ~SimulationServices();
  SimulationServices(const SimulationServices&) = delete;
  SimulationServices& operator=(const SimulationServices&) = delete;

  /// After every step, on the stepping thread: answers the StepSimulation calls whose steps are taken.
  void afterStep();
  /// The log lines at the end: calls answered, and the time from a call's arrival to its answer.
  std::string summary() const;

  struct Core;

 private:
  std::shared_ptr<Core> core_;
};

}  // namespace ssx::ros2
