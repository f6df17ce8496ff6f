// Engine factories and the abstract bases' out-of-line members.
#include "ode/ode_engine.hpp"

#include <ssx/error.hpp>
#include <ssx/physic_engine.hpp>
#include <ssx/render.hpp>

namespace ssx {

namespace {

// the null renderer: headless, draws nothing, counts frames
class NullRenderEngine final : public RenderEngine {
 public:
  std::string name() const override { return "null"; }
  void draw(Nanoseconds, const std::vector<RenderNode>&) override { ++frames_; }
  std::int64_t frameCount() const override { return frames_; }

 private:
  std::int64_t frames_ = 0;
};

}  // namespace

PhysicEngine::~PhysicEngine() = default;
RenderEngine::~RenderEngine() = default;

std::unique_ptr<PhysicEngine> createPhysicEngine(const PhysicsSettings& settings) {
  if (settings.engine == "ode") return std::make_unique<detail::OdeEngine>(settings);
  throw ConfigError({}, "unknown physics engine '" + settings.engine + "' (available: ode)");
}

std::unique_ptr<RenderEngine> createRenderEngine(const RenderSettings& settings) {
  if (settings.engine == "null") return std::make_unique<NullRenderEngine>();
  throw ConfigError({}, "unknown render engine '" + settings.engine + "' (available: null)");
}

}  // namespace ssx
