// The physics engine registry, the render engine factory and the abstract bases' out-of-line
// members.
#include "engines/bullet/bullet_class.hpp"
#include "engines/engine_options.hpp"
#include "engines/ode/ode_class.hpp"
#ifdef SSX_HAVE_OSMESA
#include "render/osmesa_engine.hpp"
#endif

#include <ssx/error.hpp>
#include <ssx/parameters.hpp>
#include <ssx/physic_engine.hpp>
#include <ssx/render.hpp>

#include <memory>
#include <mutex>

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

void PhysicEngine::setEnabled(int body, bool enabled) {
  (void)body;
  (void)enabled;
  throw Error("physics engine '" + name() + "' cannot take bodies out of its world (setEnabled)");
}
TaskRunner::~TaskRunner() = default;
RenderEngine::~RenderEngine() = default;

namespace {

struct EngineRegistry {
  std::mutex mutex;
  // (held by pointer: what findPhysicEngine returns stays where it is while others register)
  std::vector<std::unique_ptr<const PhysicEngineClass>> classes;
};

EngineRegistry& engineRegistry() {
  static EngineRegistry* registry = [] {
    auto* r = new EngineRegistry;  // (never destroyed: engines may be made until the process ends)
    // the built-in engines, one line each
    r->classes.push_back(std::make_unique<const PhysicEngineClass>(detail::odeEngineClass()));
    r->classes.push_back(std::make_unique<const PhysicEngineClass>(detail::bulletEngineClass()));
    return r;
  }();
  return *registry;
}

}  // namespace

Descriptor detail::engineOptions(const PhysicEngineClass& c, const Descriptor& given, std::vector<Diagnostic>& problems) {
  Descriptor values("physics", given.where());  // (named as the messages name the element)
  for (const ssx_plugin_param& p : c.settings)
    if (const auto* a = given.find(p.name)) values.set(p.name, a->value, a->where);
  problems = checkParameters(c.settings, values, PluginContext{}, c.name + " engine");
  Descriptor options(c.name, given.where());
  for (const ssx_plugin_param& p : c.settings) {
    if (const auto* a = values.find(p.name))
      options.set(p.name, a->value, a->where);
    else if (p.default_value != nullptr && p.default_value[0] != '\0')
      options.set(p.name, p.default_value, given.where());
  }
  return options;
}

void registerPhysicEngine(PhysicEngineClass engine) {
  const auto word = [](const std::string& n) {
    return !n.empty() && std::all_of(n.begin(), n.end(), [](char ch) {
      return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_';
    });
  };
  if (!word(engine.name))
    throw ConfigError({}, "a physics engine's name is lower-case letters, digits and '_', got '" + engine.name + "'");
  if (!engine.create) throw ConfigError({}, "physics engine '" + engine.name + "': no create function");
  // its declarations and defaults are checked now, not when a scene first names it
  std::vector<Diagnostic> problems;
  (void)detail::engineOptions(engine, Descriptor("physics"), problems);
  if (!problems.empty()) throw ConfigError({}, "physics engine '" + engine.name + "': " + problems.front().message);
  EngineRegistry& r = engineRegistry();
  const std::lock_guard lock(r.mutex);
  for (const auto& c : r.classes)
    if (c->name == engine.name) throw ConfigError({}, "physics engine '" + engine.name + "' is registered already");
  r.classes.push_back(std::make_unique<const PhysicEngineClass>(std::move(engine)));
}

const PhysicEngineClass* findPhysicEngine(std::string_view name) {
  EngineRegistry& r = engineRegistry();
  const std::lock_guard lock(r.mutex);
  for (const auto& c : r.classes)
    if (c->name == name) return c.get();
  return nullptr;
}

std::vector<std::string> physicEngineNames() {
  EngineRegistry& r = engineRegistry();
  const std::lock_guard lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& c : r.classes) names.push_back(c->name);
  return names;
}

std::unique_ptr<PhysicEngine> createPhysicEngine(const PhysicsSettings& settings) {
  const PhysicEngineClass* c = findPhysicEngine(settings.engine);
  if (c == nullptr) {
    std::string names;
    for (const auto& n : physicEngineNames()) names += (names.empty() ? "" : ", ") + n;
    throw ConfigError({}, "unknown physics engine '" + settings.engine + "' (available: " + names + ")");
  }
  PhysicsSettings s = settings;
  std::vector<Diagnostic> problems;
  // (options named for another engine are that engine's: this one starts from its defaults)
  const bool own = settings.options.name().empty() || settings.options.name() == c->name;
  s.options = detail::engineOptions(*c, own ? settings.options : Descriptor(), problems);
  if (!problems.empty()) throw ConfigError(problems.front().where, problems.front().message);
  return c->create(s);
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
