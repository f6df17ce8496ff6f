// Bullet as a scene chooses it: its settings declared (the attributes of <physics
// engine="bullet">), read into BulletSettings and back.
#include "engines/bullet/bullet_class.hpp"
#include "engines/bullet/bullet_engine.hpp"

namespace ssx::detail {

namespace {

using namespace param;

constexpr ssx_plugin_param kBulletSettings[] = {
    integer("iterations", "10", between(1, 100'000), "sequential-impulse solver iterations per substep"),
    real("erp", "0.2", "", between(0, 1), "error reduction of contacts (Bullet's erp2)"),
    real("cfm", "0", "", between(0, 1), "constraint force mixing (Bullet's globalCfm)"),
    flag("split_impulse", "true", "deep penetrations pushed out without adding momentum"),
    real("split_impulse_threshold", "-0.04", "m", above(-1) & atMost(0),
         "a penetration depth (<= 0): shallower ones are pushed out through the velocity"),
    real("linear_slop", "0", "m", nonNegative() & below(1), "penetration allowed at rest"),
};

}  // namespace

PhysicEngineClass bulletEngineClass() {
  PhysicEngineClass c;
  c.name = "bullet";
  c.doc = "Bullet's rigid bodies with its sequential-impulse solver";
  c.settings.assign(std::begin(kBulletSettings), std::end(kBulletSettings));
  c.create = [](const PhysicsSettings& s) -> std::unique_ptr<PhysicEngine> { return std::make_unique<BulletEngine>(s); };
  c.configure = [](const Descriptor& v, PhysicsSettings& s) {
    BulletSettings& b = s.bullet;
    b.iterations = static_cast<int>(v.get<std::int64_t>("iterations"));
    b.erp = v.get<double>("erp");
    b.cfm = v.get<double>("cfm");
    b.split_impulse = v.get<bool>("split_impulse");
    b.split_impulse_threshold = v.get<double>("split_impulse_threshold");
    b.linear_slop = v.get<double>("linear_slop");
  };
  c.describe = [](const PhysicsSettings& s, Descriptor& v) {
    const BulletSettings& b = s.bullet;
    v.set("iterations", std::int64_t{b.iterations})
        .set("erp", b.erp)
        .set("cfm", b.cfm)
        .set("split_impulse", b.split_impulse)
        .set("split_impulse_threshold", b.split_impulse_threshold)
        .set("linear_slop", b.linear_slop);
  };
  return c;
}

}  // namespace ssx::detail
