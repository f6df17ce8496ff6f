#pragma once
// Who may write command buffers on this thread right now. Set by the Environment around each
// plugin call in the parallel phases; outside a step, the embedding program may write anything.

namespace ssx {
class Artifact;
}

namespace ssx::detail {

struct PhaseGuard {
  // one thread-local object, not three: in a shared library each thread-local costs a call to
  // find it, and a guard is set around every plugin call of every step
  struct State {
    bool in_phase = false;             // inside a parallel phase
    const Artifact* writer = nullptr;  // the artifact whose driver runs, or nullptr
    const char* role = "";             // "driver", "sensor", "callback" for messages
  };
  static thread_local State now;

  PhaseGuard(const Artifact* w, const char* r) : state_(now), saved_(state_) { state_ = State{true, w, r}; }
  ~PhaseGuard() { state_ = saved_; }
  PhaseGuard(const PhaseGuard&) = delete;
  PhaseGuard& operator=(const PhaseGuard&) = delete;

 private:
  State& state_;
  State saved_;
};

}  // namespace ssx::detail
