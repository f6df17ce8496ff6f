#pragma once
// Who may write command buffers on this thread right now. Set by the Environment around each
// plugin call in the parallel phases; outside a step, the embedding program may write anything.

namespace ssx {
class Artifact;
}

namespace ssx::detail {

struct PhaseGuard {
  static thread_local bool in_phase;           // inside a parallel phase
  static thread_local const Artifact* writer;  // the artifact whose driver runs, or nullptr
  static thread_local const char* role;        // "driver", "sensor", "callback" for messages

  PhaseGuard(const Artifact* w, const char* r) : saved_in_(in_phase), saved_writer_(writer), saved_role_(role) {
    in_phase = true;
    writer = w;
    role = r;
  }
  ~PhaseGuard() {
    in_phase = saved_in_;
    writer = saved_writer_;
    role = saved_role_;
  }
  PhaseGuard(const PhaseGuard&) = delete;
  PhaseGuard& operator=(const PhaseGuard&) = delete;

 private:
  bool saved_in_;
  const Artifact* saved_writer_;
  const char* saved_role_;
};

}  // namespace ssx::detail
