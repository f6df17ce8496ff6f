// ODE as a scene chooses it: its settings declared (the attributes of <physics engine="ode">),
// read into OdeSettings and back.
#include "engines/ode/ode_class.hpp"
#include "engines/ode/ode_engine.hpp"

namespace ssx::detail {

namespace {

using namespace param;

constexpr ssx_plugin_param kOdeSettings[] = {
    choice("solver", "quickstep", "quickstep exact",
           "quickstep: iterative, O(n) in the constraints; exact: ODE's direct LCP solver, O(n^3) per island"),
    integer("iterations", "20", between(1, 100'000), "QuickStep iterations per step"),
    real("sor", "1.3", "", positive(), "QuickStep successive over-relaxation"),
    real("erp", "0.2", "", positive(), "error reduction of joints"),
    real("cfm", "1e-9", "", positive(), "constraint force mixing of joints"),
    real("contact_soft_erp", "0.2", "", positive(), "error reduction of contacts"),
    real("contact_soft_cfm", "1e-6", "", positive(), "constraint force mixing of contacts (softness)"),
    real("contact_surface_layer", "0.001", "m", nonNegative() & below(1),
         "penetration allowed at rest, for resting stability"),
    integer("max_contacts", "8", between(1, 1024), "contact points per pair of shapes"),
    integer("partitions", "16", between(1, 1024),
            "worlds the bodies are spread over, stepped in parallel (bodies in contact share one); results do not "
            "depend on the thread count"),
    flag("integrate_free_bodies", "true",
         "bodies no contact or joint holds are stepped with QuickStep's arithmetic outside ODE's world step (the same "
         "bits, faster); false hands every body to ODE"),
};

}  // namespace

PhysicEngineClass odeEngineClass() {
  PhysicEngineClass c;
  c.name = "ode";
  c.doc = "the Open Dynamics Engine: rigid bodies, joints and contacts (the default)";
  c.settings.assign(std::begin(kOdeSettings), std::end(kOdeSettings));
  c.create = [](const PhysicsSettings& s) -> std::unique_ptr<PhysicEngine> { return std::make_unique<OdeEngine>(s); };
  c.configure = [](const Descriptor& v, PhysicsSettings& s) {
    OdeSettings& o = s.ode;
    o.solver = v.get<std::string>("solver") == "exact" ? OdeSettings::Solver::Exact : OdeSettings::Solver::QuickStep;
    o.iterations = static_cast<int>(v.get<std::int64_t>("iterations"));
    o.sor = v.get<double>("sor");
    o.erp = v.get<double>("erp");
    o.cfm = v.get<double>("cfm");
    o.contact_soft_erp = v.get<double>("contact_soft_erp");
    o.contact_soft_cfm = v.get<double>("contact_soft_cfm");
    o.contact_surface_layer = v.get<double>("contact_surface_layer");
    o.max_contacts = static_cast<int>(v.get<std::int64_t>("max_contacts"));
    o.partitions = static_cast<int>(v.get<std::int64_t>("partitions"));
    o.integrate_free_bodies = v.get<bool>("integrate_free_bodies");
  };
  c.describe = [](const PhysicsSettings& s, Descriptor& v) {
    const OdeSettings& o = s.ode;
    v.set("solver", o.solver == OdeSettings::Solver::Exact ? "exact" : "quickstep")
        .set("iterations", std::int64_t{o.iterations})
        .set("sor", o.sor)
        .set("erp", o.erp)
        .set("cfm", o.cfm)
        .set("contact_soft_erp", o.contact_soft_erp)
        .set("contact_soft_cfm", o.contact_soft_cfm)
        .set("contact_surface_layer", o.contact_surface_layer)
        .set("max_contacts", std::int64_t{o.max_contacts})
        .set("partitions", std::int64_t{o.partitions})
        .set("integrate_free_bodies", o.integrate_free_bodies);
  };
  return c;
}

}  // namespace ssx::detail
