#include "ode/ode_engine.hpp"

#include <ssx/error.hpp>

#include <atomic>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <mutex>

namespace ssx::detail {

namespace {

// ODE's process-wide initialisation, reference-counted across engines; `generation` changes on
// every fresh init so that threads know to allocate their per-thread data again
std::mutex g_ode_mutex;
int g_ode_users = 0;
unsigned g_ode_generation = 0;

// ODE keeps the seed that QuickStep uses to reorder constraints in one global; each world keeps
// its own copy and swaps it in around its step under this lock, so worlds never disturb each other
std::mutex g_ode_step_mutex;

// set once ODE reported an internal error: its state (worlds, the threading job list) can no
// longer be torn down safely, so nothing of it is freed from then on
std::atomic<bool> g_ode_poisoned{false};

// ODE reports internal errors (a NaN quaternion, say) through handlers that abort by default;
// ours throw instead, so the Environment can stop the run with a StepError and clean up
[[noreturn]] void throwOdeError(int code, const char* format, va_list args) {
  g_ode_poisoned = true;
  char text[512];
  std::vsnprintf(text, sizeof text, format, args);
  throw Error("ode internal error " + std::to_string(code) + ": " + text);
}

void acquireOde() {
  std::lock_guard lock(g_ode_mutex);
  if (g_ode_users++ == 0) {
    dInitODE2(0);
    dSetErrorHandler(&throwOdeError);
    dSetDebugHandler(&throwOdeError);
    ++g_ode_generation;
  }
}

void releaseOde() {
  std::lock_guard lock(g_ode_mutex);
  if (--g_ode_users == 0 && !g_ode_poisoned) dCloseODE();
}

// every thread that calls into ODE needs its own collision data
void ensureThreadData() {
  thread_local unsigned seen_generation = 0;
  const unsigned generation = g_ode_generation;
  if (seen_generation != generation) {
    if (!dAllocateODEDataForThread(dAllocateMaskAll))
      throw Error("ode: could not allocate per-thread data (out of memory?)");
    seen_generation = generation;
  }
}

void toOde(const Quat& q, dQuaternion out) {
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

}  // namespace

OdeEngine::OdeEngine(const PhysicsSettings& settings) : settings_(settings) {
  acquireOde();
  ensureThreadData();
  world_ = dWorldCreate();
  const Vec3& g = settings_.gravity;
  dWorldSetGravity(world_, g.x(), g.y(), g.z());
  dWorldSetERP(world_, settings_.erp);
  dWorldSetCFM(world_, settings_.cfm);
  dWorldSetQuickStepNumIterations(world_, settings_.iterations);
  dWorldSetQuickStepW(world_, settings_.sor);
  dWorldSetContactSurfaceLayer(world_, settings_.contact_surface_layer);
  dWorldSetAutoDisableFlag(world_, 0);

  if (settings_.broadphase == PhysicsSettings::Broadphase::QuadTree) {
    dVector3 c{settings_.quadtree_center.x(), settings_.quadtree_center.y(), settings_.quadtree_center.z(), 0};
    dVector3 e{settings_.quadtree_extents.x(), settings_.quadtree_extents.y(), settings_.quadtree_extents.z(), 0};
    space_ = dQuadTreeSpaceCreate(nullptr, c, e, settings_.quadtree_depth);
  } else {
    space_ = dSweepAndPruneSpaceCreate(nullptr, dSAP_AXES_XYZ);
  }
  dSpaceSetCleanup(space_, 1);
  contact_group_ = dJointGroupCreate(0);
  contact_scratch_.resize(static_cast<std::size_t>(std::max(1, settings_.max_contacts)));
}

OdeEngine::~OdeEngine() {
  if (g_ode_poisoned) {
    releaseOde();  // the world is leaked on purpose: ODE cannot tear it down after an internal error
    return;
  }
  ensureThreadData();
  dJointGroupDestroy(contact_group_);
  dSpaceDestroy(space_);  // destroys its geoms (cleanup mode)
  dWorldDestroy(world_);  // destroys its bodies
  releaseOde();
}

dGeomID OdeEngine::createGeom(const Shape& s) {
  switch (s.kind) {
    case Shape::Kind::Box:
      return dCreateBox(space_, s.size.x(), s.size.y(), s.size.z());
    case Shape::Kind::Sphere:
      return dCreateSphere(space_, s.radius);
    case Shape::Kind::Cylinder:
      return dCreateCylinder(space_, s.radius, s.length);
    case Shape::Kind::Capsule:
      return dCreateCapsule(space_, s.radius, s.length);
    case Shape::Kind::Plane:
      break;
  }
  return nullptr;
}

int OdeEngine::addBody(const MassProperties& mass, const std::vector<Shape>& shapes, const BodyState& state) {
  ensureThreadData();
  dBodyID body = dBodyCreate(world_);
  dMass m;
  const Mat3& j = mass.inertia;
  // the body frame is the centre-of-mass frame: ODE requires the centre at the origin
  dMassSetParameters(&m, mass.mass, 0, 0, 0, j(0, 0), j(1, 1), j(2, 2), j(0, 1), j(0, 2), j(1, 2));
  dBodySetMass(body, &m);
  for (const auto& s : shapes) {
    if (s.kind == Shape::Kind::Plane) throw Error("ode: a plane cannot belong to a dynamic body");
    dGeomID g = createGeom(s);
    dGeomSetBody(g, body);
    dQuaternion q;
    toOde(s.pose.orientation, q);
    dGeomSetOffsetPosition(g, s.pose.position.x(), s.pose.position.y(), s.pose.position.z());
    dGeomSetOffsetQuaternion(g, q);
  }
  bodies_.push_back(body);
  setState(static_cast<int>(bodies_.size() - 1), state);
  return static_cast<int>(bodies_.size() - 1);
}

void OdeEngine::addStatic(const std::vector<Shape>& shapes, const Pose& pose) {
  ensureThreadData();
  for (const auto& s : shapes) {
    const Pose world = pose * s.pose;
    if (s.kind == Shape::Kind::Plane) {
      const Vec3 n = world.orientation * Vec3::UnitZ();
      dCreatePlane(space_, n.x(), n.y(), n.z(), n.dot(world.position));
      continue;
    }
    dGeomID g = createGeom(s);
    dQuaternion q;
    toOde(world.orientation, q);
    dGeomSetPosition(g, world.position.x(), world.position.y(), world.position.z());
    dGeomSetQuaternion(g, q);
  }
}

void OdeEngine::nearCallback(void* data, dGeomID a, dGeomID b) {
  auto* self = static_cast<OdeEngine*>(data);
  dBodyID ba = dGeomGetBody(a);
  dBodyID bb = dGeomGetBody(b);
  if (ba == nullptr && bb == nullptr) return;  // two static geoms
  if (ba != nullptr && bb != nullptr && dAreConnectedExcluding(ba, bb, dJointTypeContact)) return;
  const int n = dCollide(a, b, static_cast<int>(self->contact_scratch_.size()), &self->contact_scratch_[0].geom,
                         sizeof(dContact));
  const PhysicsSettings& s = self->settings_;
  for (int i = 0; i < n; ++i) {
    dContact& c = self->contact_scratch_[static_cast<std::size_t>(i)];
    c.surface.mode = dContactApprox1 | dContactSoftCFM | dContactSoftERP;
    c.surface.mu = s.friction;
    c.surface.soft_cfm = s.contact_soft_cfm;
    c.surface.soft_erp = s.contact_soft_erp;
    if (s.restitution > 0) {
      c.surface.mode |= dContactBounce;
      c.surface.bounce = s.restitution;
      c.surface.bounce_vel = 0.01;
    }
    dJointID j = dJointCreateContact(self->world_, self->contact_group_, &c);
    dJointAttach(j, ba, bb);
  }
  self->contact_count_ += static_cast<std::size_t>(n);
}

void OdeEngine::step(Nanoseconds dt, std::span<const Wrench> wrenches) {
  ensureThreadData();
  const int substeps = std::max(1, settings_.substeps);
  const double h = toSeconds(dt) / substeps;
  contact_count_ = 0;
  std::lock_guard lock(g_ode_step_mutex);
  const unsigned long outer_seed = dRandGetSeed();
  dRandSetSeed(rand_seed_);
  struct RestoreSeed {
    unsigned long& mine;
    unsigned long outer;
    ~RestoreSeed() {
      mine = dRandGetSeed();
      dRandSetSeed(outer);
    }
  } restore{rand_seed_, outer_seed};
  for (int k = 0; k < substeps; ++k) {
    // ODE clears force accumulators after each step: apply the held wrenches every substep
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
      const Wrench& w = wrenches[i];
      dBodyAddForce(bodies_[i], w.force.x(), w.force.y(), w.force.z());
      dBodyAddTorque(bodies_[i], w.torque.x(), w.torque.y(), w.torque.z());
    }
    dSpaceCollide(space_, this, &OdeEngine::nearCallback);
    if (settings_.solver == PhysicsSettings::Solver::Exact)
      dWorldStep(world_, h);
    else
      dWorldQuickStep(world_, h);
    dJointGroupEmpty(contact_group_);
  }
}

void OdeEngine::readStates(std::span<BodyState> out) const {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    dBodyID b = bodies_[i];
    const dReal* p = dBodyGetPosition(b);
    const dReal* q = dBodyGetQuaternion(b);
    const dReal* v = dBodyGetLinearVel(b);
    const dReal* w = dBodyGetAngularVel(b);
    BodyState& s = out[i];
    s.pose.position = Vec3(p[0], p[1], p[2]);
    s.pose.orientation = Quat(q[0], q[1], q[2], q[3]);
    s.linear_velocity = Vec3(v[0], v[1], v[2]);
    s.angular_velocity = Vec3(w[0], w[1], w[2]);
  }
}

void OdeEngine::setState(int body, const BodyState& s) {
  ensureThreadData();
  dBodyID b = bodies_.at(static_cast<std::size_t>(body));
  dQuaternion q;
  toOde(s.pose.orientation.normalized(), q);
  dBodySetPosition(b, s.pose.position.x(), s.pose.position.y(), s.pose.position.z());
  dBodySetQuaternion(b, q);
  dBodySetLinearVel(b, s.linear_velocity.x(), s.linear_velocity.y(), s.linear_velocity.z());
  dBodySetAngularVel(b, s.angular_velocity.x(), s.angular_velocity.y(), s.angular_velocity.z());
}

// per body: position, quaternion, rotation matrix (ODE keeps both; R is not recomputed from a
// restored q, which could differ in the last bit), linear and angular velocity
namespace {
constexpr std::size_t kOdeBodyReals = 3 + 4 + 12 + 3 + 3;
constexpr double kMaxRestoredPosition = 1e9;  // m
}

void OdeEngine::saveState(StateWriter& out) const {
  out.write(static_cast<std::uint64_t>(rand_seed_));
  out.write(static_cast<std::uint64_t>(bodies_.size()));
  for (dBodyID b : bodies_) {
    out.bytes(dBodyGetPosition(b), 3 * sizeof(dReal));
    out.bytes(dBodyGetQuaternion(b), 4 * sizeof(dReal));
    out.bytes(dBodyGetRotation(b), 12 * sizeof(dReal));
    out.bytes(dBodyGetLinearVel(b), 3 * sizeof(dReal));
    out.bytes(dBodyGetAngularVel(b), 3 * sizeof(dReal));
  }
}

void OdeEngine::restoreState(StateReader& in) {
  // everything is read before anything is changed
  const auto seed = in.get<std::uint64_t>();
  const auto count = in.get<std::uint64_t>();
  if (count != bodies_.size())
    throw StateError("ode: the saved state has " + std::to_string(count) + " bodies, this world " +
                     std::to_string(bodies_.size()));
  std::vector<dReal> values(bodies_.size() * kOdeBodyReals);
  in.bytes(values.data(), values.size() * sizeof(dReal));
  // a state ODE could have produced: finite, a unit quaternion with its rotation matrix, within the
  // speed guards and the positions ODE's collision code handles (anything else could make ODE
  // fail inside its step, where it cannot be recovered)
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const dReal* v = values.data() + i * kOdeBodyReals;
    auto bad = [&](const std::string& what) {
      return StateError("ode: body " + std::to_string(i) + " in the saved state " + what);
    };
    for (std::size_t k = 0; k < kOdeBodyReals; ++k)
      if (!std::isfinite(v[k])) throw bad("has a NaN or infinite value");
    const Vec3 position(v[0], v[1], v[2]);
    if (position.cwiseAbs().maxCoeff() > kMaxRestoredPosition) throw bad("is more than 1e9 m from the origin");
    const Quat q(v[3], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-9) throw bad("has a quaternion that is not of unit length");
    const Mat3 expected = q.toRotationMatrix();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        if (std::abs(v[7 + 4 * r + c] - expected(r, c)) > 1e-9) throw bad("has a rotation matrix that is not its quaternion's");
    if (Vec3(v[19], v[20], v[21]).norm() > settings_.max_linear_speed ||
        Vec3(v[22], v[23], v[24]).norm() > settings_.max_angular_speed)
      throw bad("is faster than max_linear_speed or max_angular_speed");
  }
  ensureThreadData();
  rand_seed_ = static_cast<unsigned long>(seed);
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    dBodyID b = bodies_[i];
    const dReal* v = values.data() + i * kOdeBodyReals;
    dBodySetPosition(b, v[0], v[1], v[2]);  // also marks the body's geoms as moved
    dBodySetQuaternion(b, v + 3);
    // ODE normalises a quaternion it is given; the saved bits are already what its step left
    std::memcpy(const_cast<dReal*>(dBodyGetQuaternion(b)), v + 3, 4 * sizeof(dReal));
    std::memcpy(const_cast<dReal*>(dBodyGetRotation(b)), v + 7, 12 * sizeof(dReal));
    dBodySetLinearVel(b, v[19], v[20], v[21]);
    dBodySetAngularVel(b, v[22], v[23], v[24]);
  }
}

}  // namespace ssx::detail
