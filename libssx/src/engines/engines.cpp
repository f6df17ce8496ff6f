// Engine factories and the abstract bases' out-of-line members.
#include "engines/bullet/bullet_engine.hpp"
#include "engines/ode/ode_engine.hpp"
#ifdef SSX_HAVE_OSMESA
#include "render/osmesa_engine.hpp"
#endif

#include <ssx/error.hpp>
#include <ssx/physic_engine.hpp>
#include <ssx/render.hpp>

namespace ssx {

namespace {

// the null renderer: headless, draws nothing
class NullRenderEngine final : public RenderEngine {
 public:
  std::string name() const override { return "null"; }
  bool drawsPixels() const override { return false; }
  void renderView(const CameraView&, const std::vector<RenderNode>&, const Color&, Image&) override {
    throw Error("the null render engine draws no images: choose engine=\"osmesa\" in <render> or --render osmesa");
  }
};

}  // namespace

PhysicEngine::~PhysicEngine() = default;
TaskRunner::~TaskRunner() = default;
RenderEngine::~RenderEngine() = default;

std::vector<std::string> physicEngineNames() { return {"ode", "bullet"}; }

std::unique_ptr<PhysicEngine> createPhysicEngine(const PhysicsSettings& settings) {
  if (settings.engine == "ode") return std::make_unique<detail::OdeEngine>(settings);
  if (settings.engine == "bullet") return std::make_unique<detail::BulletEngine>(settings);
  throw ConfigError({}, "unknown physics engine '" + settings.engine + "' (available: ode, bullet)");
}

std::vector<std::string> renderEngineNames() {
#ifdef SSX_HAVE_OSMESA
  return {"null", "osmesa"};
#else
  return {"null"};
#endif
}

std::unique_ptr<RenderEngine> createRenderEngine(const RenderSettings& settings) {
  if (settings.engine == "null") return std::make_unique<NullRenderEngine>();
#ifdef SSX_HAVE_OSMESA
  if (settings.engine == "osmesa") return std::make_unique<detail::OsmesaRenderEngine>();
#else
  if (settings.engine == "osmesa")
    throw ConfigError({}, "render engine 'osmesa' is not in this build of ssx: install libosmesa6-dev and rebuild");
#endif
  std::string names;
  for (const auto& n : renderEngineNames()) names += (names.empty() ? "" : ", ") + n;
  throw ConfigError({}, "unknown render engine '" + settings.engine + "' (available: " + names + ")");
}

}  // namespace ssx
