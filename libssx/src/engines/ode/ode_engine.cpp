#include "engines/ode/ode_engine.hpp"

#include "engines/articulations.hpp"
#include "engines/state_checks.hpp"

#include <ssx/error.hpp>

#include <dlfcn.h>

#include <atomic>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <algorithm>
#include <cstdint>
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

// The seed of the world being stepped on this thread, or null. QuickStep reorders constraints with
// dRandInt, which ODE draws (dRand) from one process-wide seed: stepped at the same time, worlds
// with contacts would take numbers from each other. ssx defines dRand itself (below); ODE calls it
// through its PLT, so on this thread the numbers come from the world's own seed. Whether the
// definition really takes ODE's place (it does when libssx comes before libode in the lookup
// order, as when linked or dlopen'd as usual) is checked once, by stepping a small world; if not,
// worlds with contacts take turns under g_ode_step_mutex with their seed swapped in, as before.
thread_local unsigned long* t_world_seed = nullptr;
thread_local bool t_interposed_call = false;

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

void toOde(const Quat& q, dQuaternion out) {
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

// does ODE's QuickStep call our dRandInt? (a world with one constrained pair, stepped once)
bool seedIsPerWorld() {
  static const bool per_world = [] {
    dWorldID w = dWorldCreate();
    dJointGroupID group = dJointGroupCreate(0);
    dBodyID a = dBodyCreate(w);
    dBodyID b = dBodyCreate(w);
    dBodySetPosition(b, 0, 0, 0.5);
    dJointID j = dJointCreateBall(w, group);
    dJointAttach(j, a, b);
    dJointSetBallAnchor(j, 0, 0, 0.25);
    unsigned long seed = 1;
    t_world_seed = &seed;
    t_interposed_call = false;
    dWorldQuickStep(w, 0.001);
    const bool called = t_interposed_call;
    t_world_seed = nullptr;
    dJointGroupDestroy(group);
    dWorldDestroy(w);
    return called;
  }();
  return per_world;
}

}  // namespace

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

}  // namespace ssx::detail

// ODE's dRand, from the stepping world's own seed when there is one (see t_world_seed), else
// ODE's own, found behind this definition. The generator is ODE's (a 32-bit linear congruence) and
// dRandInt stays ODE's: the numbers are those ODE draws with that seed set, to the bit.
extern "C" __attribute__((visibility("default"))) unsigned long dRand() {
  using ssx::detail::t_world_seed;
  if (t_world_seed != nullptr) {
    ssx::detail::t_interposed_call = true;
    *t_world_seed = (1664525UL * *t_world_seed + 1013904223UL) & 0xffffffffUL;
    return *t_world_seed;
  }
  static const auto ode = reinterpret_cast<unsigned long (*)()>(dlsym(RTLD_NEXT, "dRand"));
  if (ode != nullptr && ode != &dRand) return ode();
  // (no other definition: ODE's generator on its own seed, not atomically)
  const unsigned long next = (1664525UL * dRandGetSeed() + 1013904223UL) & 0xffffffffUL;
  dRandSetSeed(next);
  return next;
}

namespace ssx::detail {

OdeEngine::OdeEngine(const PhysicsSettings& settings) : settings_(settings) {
  acquireOde();
  try {
    ensureThreadData();
    (void)seedIsPerWorld();  // (checked here, on the caller's thread, once per process)
    partitions_.resize(static_cast<std::size_t>(std::max(1, settings_.ode.partitions)));
    for (int k = 0; k < 3; ++k) gravity_[k] = settings_.gravity[k];
    integrate_free_ = settings_.ode.integrate_free_bodies && settings_.ode.solver == OdeSettings::Solver::QuickStep;
    openWorld(partitions_[0]);  // (the others when a body first goes there: see openWorld)
  } catch (...) {
    for (Partition& p : partitions_) {
      if (p.contacts != nullptr) dJointGroupDestroy(p.contacts);
      if (p.world != nullptr) dWorldDestroy(p.world);
      if (p.threading != nullptr) dThreadingFreeImplementation(p.threading);
    }
    releaseOde();
    throw;
  }

  contacts_per_pair_ = static_cast<std::size_t>(std::max(1, settings_.ode.max_contacts));
}

void OdeEngine::openWorld(Partition& p) {
  // worlds are made when a body first goes there: a world of a few bodies uses one of its
  // partitions, and a thousand copies of it would otherwise keep thousands of idle ODE worlds
  if (p.world != nullptr) return;
  p.world = dWorldCreate();
  const Vec3& g = settings_.gravity;
  dWorldSetGravity(p.world, g.x(), g.y(), g.z());
  dWorldSetERP(p.world, settings_.ode.erp);
  dWorldSetCFM(p.world, settings_.ode.cfm);
  dWorldSetQuickStepNumIterations(p.world, settings_.ode.iterations);
  dWorldSetQuickStepW(p.world, settings_.ode.sor);
  dWorldSetContactSurfaceLayer(p.world, settings_.ode.contact_surface_layer);
  dWorldSetAutoDisableFlag(p.world, 0);
  // each world its own (single-threaded) threading implementation: ODE's default one is
  // shared by every world and not meant for worlds stepped at the same time
  p.threading = dThreadingAllocateSelfThreadedImplementation();
  if (p.threading == nullptr) throw Error("ode: could not allocate a threading implementation");
  dWorldSetStepThreadingImplementation(p.world, dThreadingImplementationGetFunctions(p.threading), p.threading);
  p.contacts = dJointGroupCreate(0);
}

OdeEngine::~OdeEngine() {
  if (g_ode_poisoned) {
    releaseOde();  // the worlds are leaked on purpose: ODE cannot tear them down after an internal error
    return;
  }
  ensureThreadData();
  for (const Body& b : bodies_)
    for (const Geom& g : b.geoms) dGeomDestroy(g.id);
  for (dGeomID g : static_geoms_) dGeomDestroy(g);
  for (dGeomID g : free_rays_) dGeomDestroy(g);
  for (Partition& p : partitions_) {
    if (p.world == nullptr) continue;  // (never used)
    if (p.contacts != nullptr) dJointGroupDestroy(p.contacts);
    dWorldSetStepThreadingImplementation(p.world, nullptr, nullptr);
    dWorldDestroy(p.world);  // destroys its bodies
    if (p.threading != nullptr) dThreadingFreeImplementation(p.threading);
  }
  releaseOde();
}

dGeomID createOdeGeom(const Shape& s, OdeMeshes& meshes, bool is_static, Vec3& centre) {
  centre = Vec3::Zero();
  switch (s.kind) {
    case Shape::Kind::Box:
      return dCreateBox(nullptr, s.size.x(), s.size.y(), s.size.z());
    case Shape::Kind::Sphere:
      return dCreateSphere(nullptr, s.radius);
    case Shape::Kind::Cylinder:
      return dCreateCylinder(nullptr, s.radius, s.length);
    case Shape::Kind::Capsule:
      return dCreateCapsule(nullptr, s.radius, s.length);
    case Shape::Kind::Mesh:
      return meshes.create(s, is_static, centre);
    case Shape::Kind::Plane:
      break;
  }
  return nullptr;
}

int OdeEngine::addBody(const MassProperties& mass, const std::vector<Shape>& shapes, const BodyState& state) {
  ensureThreadData();
  const int index = static_cast<int>(bodies_.size());
  Body body;
  body.home = homeOf(index);
  body.partition = body.home;
  Partition& p = partitions_[static_cast<std::size_t>(body.home)];
  openWorld(p);
  used_partitions_ = std::max(used_partitions_, static_cast<std::size_t>(body.home) + 1);
  body.id = dBodyCreate(p.world);
  const Mat3& j = mass.inertia;
  // the body frame is the centre-of-mass frame: ODE requires the centre at the origin
  dMassSetParameters(&body.mass, mass.mass, 0, 0, 0, j(0, 0), j(1, 1), j(2, 2), j(0, 1), j(0, 2), j(1, 2));
  dBodySetMass(body.id, &body.mass);
  body.added = body.mass;
  dBodySetData(body.id, reinterpret_cast<void*>(static_cast<std::intptr_t>(index)));
  for (const auto& s : shapes) {
    if (s.kind == Shape::Kind::Plane) {
      dBodyDestroy(body.id);
      for (const Geom& g : body.geoms) dGeomDestroy(g.id);
      throw Error("ode: a plane cannot belong to a dynamic body");
    }
    Vec3 centre;
    Geom g{createOdeGeom(s, meshes_, false, centre), {}, {}, 0.0};
    switch (s.kind) {
      case Shape::Kind::Box: g.diameter = s.size.norm(); break;
      case Shape::Kind::Sphere: g.diameter = 2 * s.radius; break;
      case Shape::Kind::Cylinder: g.diameter = 2 * std::hypot(s.radius, s.length / 2); break;
      case Shape::Kind::Capsule: g.diameter = 2 * s.radius + s.length; break;
      case Shape::Kind::Mesh: g.diameter = 2 * s.mesh->min.cwiseAbs().cwiseMax(s.mesh->max.cwiseAbs()).norm(); break;
      case Shape::Kind::Plane: break;
    }
    // the offset as dGeomSetOffsetPosition and dGeomSetOffsetQuaternion would keep it
    const Vec3 at = s.pose.transformPoint(centre);
    g.offset_position[0] = at.x();
    g.offset_position[1] = at.y();
    g.offset_position[2] = at.z();
    g.offset_position[3] = 0;
    dQuaternion q;
    toOde(s.pose.orientation, q);
    dRfromQ(g.offset_rotation, q);
    // which body a geom belongs to, for the contact callback (static geoms: -1 - their group)
    dGeomSetData(g.id, reinterpret_cast<void*>(static_cast<std::intptr_t>(index) + 1));
    body.geoms.push_back(g);
  }
  p.order.push_back(index);
  bodies_.push_back(std::move(body));
  cacheFreeStep(bodies_.back());
  proxies_stale_ = true;
  setState(index, state);
  return index;
}

void OdeEngine::setKinematic(int index) {
  Body& body = bodies_.at(static_cast<std::size_t>(index));
  ensureThreadData();
  dBodySetKinematic(body.id);
  body.kinematic = true;
  cacheFreeStep(body);
  proxies_stale_ = true;
}

bool OdeEngine::isKinematic(int index) const { return bodies_.at(static_cast<std::size_t>(index)).kinematic; }

void OdeEngine::setMassScale(int index, double mass_factor, double inertia_factor) {
  Body& body = bodies_.at(static_cast<std::size_t>(index));
  if (body.kinematic) return;
  body.mass = body.added;  // the factors never compound
  body.mass.mass *= mass_factor;
  for (dReal& i : body.mass.I) i *= inertia_factor;
  dBodySetMass(body.id, &body.mass);
  cacheFreeStep(body);
}

int OdeEngine::addStatic(const std::vector<Shape>& shapes, const Pose& pose) {
  ensureThreadData();
  const int group = static_groups_++;
  void* const data = reinterpret_cast<void*>(static_cast<std::intptr_t>(-1 - group));
  for (const auto& s : shapes) {
    const Pose world = pose * s.pose;
    if (s.kind == Shape::Kind::Plane) {
      const Vec3 n = world.orientation * Vec3::UnitZ();
      dGeomID plane = dCreatePlane(nullptr, n.x(), n.y(), n.z(), n.dot(world.position));
      dGeomSetData(plane, data);
      static_geoms_.push_back(plane);
      planes_.push_back(plane);
      dVector4 params;
      dGeomPlaneGetParams(plane, params);  // (normalised as ODE keeps it)
      planes_params_.push_back({params[0], params[1], params[2], params[3]});
      continue;
    }
    Vec3 centre;
    dGeomID g = createOdeGeom(s, meshes_, true, centre);
    dQuaternion q;
    toOde(world.orientation, q);
    const Vec3 at = world.transformPoint(centre);
    dGeomSetPosition(g, at.x(), at.y(), at.z());
    dGeomSetQuaternion(g, q);
    dGeomSetData(g, data);
    static_geoms_.push_back(g);
  }
  proxies_stale_ = true;
  return group;
}

// A body's state bit for bit: position, quaternion, rotation matrix (ODE keeps both; R is not
// recomputed from a copied q, which could differ in the last bit), linear and angular velocity.
void readOdeBits(dBodyID b, dReal* out) {
  std::memcpy(out, dBodyGetPosition(b), 3 * sizeof(dReal));
  std::memcpy(out + 3, dBodyGetQuaternion(b), 4 * sizeof(dReal));
  std::memcpy(out + 7, dBodyGetRotation(b), 12 * sizeof(dReal));
  std::memcpy(out + 19, dBodyGetLinearVel(b), 3 * sizeof(dReal));
  std::memcpy(out + 22, dBodyGetAngularVel(b), 3 * sizeof(dReal));
}

void writeOdeBits(dBodyID b, const dReal* in) {
  dBodySetPosition(b, in[0], in[1], in[2]);
  dBodySetQuaternion(b, in + 3);
  // ODE normalises a quaternion it is given and derives the rotation from it: copy the bits
  std::memcpy(const_cast<dReal*>(dBodyGetQuaternion(b)), in + 3, 4 * sizeof(dReal));
  std::memcpy(const_cast<dReal*>(dBodyGetRotation(b)), in + 7, 12 * sizeof(dReal));
  dBodySetLinearVel(b, in[19], in[20], in[21]);
  dBodySetAngularVel(b, in[22], in[23], in[24]);
}

void OdeEngine::moveBody(int index, int to) {
  Body& body = bodies_[static_cast<std::size_t>(index)];
  Partition& from = partitions_[static_cast<std::size_t>(body.partition)];
  Partition& into = partitions_[static_cast<std::size_t>(to)];
  openWorld(into);
  const dBodyID old = body.id;
  const dBodyID b = dBodyCreate(into.world);
  dBodySetMass(b, &body.mass);
  if (body.kinematic) dBodySetKinematic(b);
  dBodySetData(b, dBodyGetData(old));
  dReal bits[kOdeBodyReals];
  readOdeBits(old, bits);
  writeOdeBits(b, bits);
  dBodyDestroy(old);
  body.id = b;
  cacheFreeStep(body);
  const auto it = std::find(from.order.begin(), from.order.end(), index);
  if (it != from.order.end()) from.order.erase(it);
  into.order.push_back(index);
  body.partition = to;
  used_partitions_ = std::max(used_partitions_, static_cast<std::size_t>(to) + 1);
}

void OdeEngine::solveWithOde(Partition& p, double h) {
  auto solve = [&] {
    if (settings_.ode.solver == OdeSettings::Solver::Exact)
      dWorldStep(p.world, h);
    else
      dWorldQuickStep(p.world, h);
  };
  if (!p.has_joints) {
    solve();  // no constraints: ODE draws no random numbers
    return;
  }
  if (seedIsPerWorld()) {
    t_world_seed = &p.rand_seed;
    struct Reset {
      ~Reset() { t_world_seed = nullptr; }
    } reset;
    solve();
    dJointGroupEmpty(p.contacts);
    return;
  }
  // QuickStep reorders constraints with ODE's one process-wide random seed: worlds with contacts
  // take turns, each with its own copy of the seed swapped in
  std::lock_guard lock(g_ode_step_mutex);
  const unsigned long outer_seed = dRandGetSeed();
  dRandSetSeed(p.rand_seed);
  struct RestoreSeed {
    unsigned long& mine;
    unsigned long outer;
    ~RestoreSeed() {
      mine = dRandGetSeed();
      dRandSetSeed(outer);
    }
  } restore{p.rand_seed, outer_seed};
  solve();
  dJointGroupEmpty(p.contacts);
}

void OdeEngine::step(Nanoseconds dt, std::span<const Wrench> wrenches) {
  ensureThreadData();
  const int substeps = std::max(1, settings_.substeps);
  const double h = toSeconds(dt) / substeps;
  contact_count_ = 0;
  const bool log = contact_log_.on();
  if (log) contact_log_.begin();
  seal();
  if (groups_.size() != bodies_.size()) groups_.resize(bodies_.size());
  if (labels_stale_ || articulation_.size() != bodies_.size()) refreshLabels(true);
  for (int k = 0; k < substeps; ++k) {
    // contacts in one space over every world, then the groups they make into one world each
    collide();
    groupContacts();
    for (std::size_t i = 0; i < used_partitions_; ++i) partitions_[i].has_joints = false;
    if (integrate_free_ || live_joints_ > 0)
      for (Body& body : bodies_) {
        body.constrained = body.pinned;
        if (body.pinned) partitions_[static_cast<std::size_t>(body.partition)].has_joints = true;
      }
    if (log) feedback_.assign(contacts_.size(), dJointFeedback{});
    for (std::size_t k = 0; k < contacts_.size(); ++k) {
      const dContact& c = contacts_[k];
      const auto owner_a = reinterpret_cast<std::intptr_t>(dGeomGetData(c.geom.g1));
      const auto owner_b = reinterpret_cast<std::intptr_t>(dGeomGetData(c.geom.g2));
      const dBodyID a = owner_a > 0 ? bodies_[static_cast<std::size_t>(owner_a - 1)].id : nullptr;
      const dBodyID b = owner_b > 0 ? bodies_[static_cast<std::size_t>(owner_b - 1)].id : nullptr;
      const int owner = static_cast<int>((owner_a > 0 ? owner_a : owner_b) - 1);
      Partition& p = partitions_[static_cast<std::size_t>(bodies_[static_cast<std::size_t>(owner)].partition)];
      dJointID j = dJointCreateContact(p.world, p.contacts, &c);
      dJointAttach(j, a, b);
      if (log) dJointSetFeedback(j, &feedback_[k]);
      p.has_joints = true;
      if (owner_a > 0) bodies_[static_cast<std::size_t>(owner_a - 1)].constrained = true;
      if (owner_b > 0) bodies_[static_cast<std::size_t>(owner_b - 1)].constrained = true;
    }
    contact_count_ += contacts_.size();
    // the worlds, in parallel (serially for small worlds: the same results either way)
    forEach(used_partitions_, [&](std::size_t i) { stepPartition(partitions_[i], h, wrenches); });
    if (log) logContacts(h);
  }
  if (log) contact_log_.finish();
}

void OdeEngine::logContacts(double h) {
  for (std::size_t k = 0; k < contacts_.size(); ++k) {
    const dContactGeom& g = contacts_[k].geom;
    const auto owner_a = reinterpret_cast<std::intptr_t>(dGeomGetData(g.g1));
    const auto owner_b = reinterpret_cast<std::intptr_t>(dGeomGetData(g.g2));
    // ODE's normal points into g1; the feedback's f1 is the force on the joint's first body (the
    // one that is not the static world): its part along the normal, over the substep
    const Vec3 normal(g.normal[0], g.normal[1], g.normal[2]);
    const Vec3 force(feedback_[k].f1[0], feedback_[k].f1[1], feedback_[k].f1[2]);
    // (a static geom's data is -1 - its group: addStatic)
    const auto group = static_cast<int>(-1 - std::min(owner_a, owner_b));
    contact_log_.add(owner_a > 0 ? static_cast<int>(owner_a - 1) : -1, owner_b > 0 ? static_cast<int>(owner_b - 1) : -1,
                     group, Vec3(g.pos[0], g.pos[1], g.pos[2]), normal, g.depth, std::abs(force.dot(normal)) * h);
  }
}

void OdeEngine::hotMemory(std::vector<MemoryRange>& out) const {
  out.push_back({this, sizeof *this});
  out.push_back({bodies_.data(), bodies_.size() * sizeof(Body)});
  for (std::size_t p = 0; p < used_partitions_; ++p) out.push_back({partitions_[p].world, 512});
  // (ODE's own structs: a body is about 600 bytes, a geom about 200)
  for (const Body& body : bodies_) {
    out.push_back({body.id, 640});
    out.push_back({body.geoms.data(), body.geoms.size() * sizeof(Geom)});
    for (const Geom& g : body.geoms) out.push_back({g.id, 256});
  }
  for (const dGeomID plane : planes_) out.push_back({plane, 256});
}

void OdeEngine::readStates(std::span<BodyState> out) const {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    dBodyID b = bodies_[i].id;
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
  dBodyID b = bodies_.at(static_cast<std::size_t>(body)).id;
  dQuaternion q;
  toOde(s.pose.orientation.normalized(), q);
  dBodySetPosition(b, s.pose.position.x(), s.pose.position.y(), s.pose.position.z());
  dBodySetQuaternion(b, q);
  dBodySetLinearVel(b, s.linear_velocity.x(), s.linear_velocity.y(), s.linear_velocity.z());
  dBodySetAngularVel(b, s.angular_velocity.x(), s.angular_velocity.y(), s.angular_velocity.z());
}

void OdeEngine::saveState(StateWriter& out) const {
  // per world: its random seed and its bodies in creation order (which decides the order ODE
  // solves its contact groups in); then every body
  out.write(static_cast<std::uint64_t>(partitions_.size()));
  for (const Partition& p : partitions_) {
    out.write(static_cast<std::uint64_t>(p.rand_seed));
    out.write(static_cast<std::uint64_t>(p.order.size()));
    for (const int i : p.order) out.write(static_cast<std::uint32_t>(i));
  }
  out.write(static_cast<std::uint64_t>(bodies_.size()));
  for (const Body& body : bodies_) {
    dReal bits[kOdeBodyReals];
    readOdeBits(body.id, bits);
    out.bytes(bits, sizeof bits);
  }
  saveJoints(out);
}

void OdeEngine::restoreState(StateReader& in) {
  // everything is read before anything is changed
  const auto worlds = in.get<std::uint64_t>();
  if (worlds != partitions_.size())
    throw StateError("ode: the saved state has " + std::to_string(worlds) + " partitions, this world " +
                     std::to_string(partitions_.size()));
  std::vector<unsigned long> seeds(partitions_.size());
  std::vector<std::vector<int>> orders(partitions_.size());
  std::vector<int> where(bodies_.size(), -1);
  for (std::size_t p = 0; p < partitions_.size(); ++p) {
    seeds[p] = static_cast<unsigned long>(in.get<std::uint64_t>());
    const auto size = in.get<std::uint64_t>();
    if (size > bodies_.size()) throw StateError("ode: a partition in the saved state has more bodies than the world");
    for (std::uint64_t k = 0; k < size; ++k) {
      const auto i = in.get<std::uint32_t>();
      if (i >= bodies_.size() || where[i] >= 0)
        throw StateError("ode: the saved state's partitions do not hold every body exactly once");
      where[i] = static_cast<int>(p);
      orders[p].push_back(static_cast<int>(i));
    }
  }
  if (std::find(where.begin(), where.end(), -1) != where.end())
    throw StateError("ode: the saved state's partitions do not hold every body exactly once");
  const auto count = in.get<std::uint64_t>();
  if (count != bodies_.size())
    throw StateError("ode: the saved state has " + std::to_string(count) + " bodies, this world " +
                     std::to_string(bodies_.size()));
  std::vector<dReal> values(bodies_.size() * kOdeBodyReals);
  in.bytes(values.data(), values.size() * sizeof(dReal));
  // a state ODE could have produced: finite, within reach and the speed guards, a unit quaternion
  // with its rotation matrix
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const dReal* v = values.data() + i * kOdeBodyReals;
    auto bad = [&](const std::string& what) {
      return StateError("ode: body " + std::to_string(i) + " in the saved state " + what);
    };
    if (const char* problem = savedBodyProblem({v, kOdeBodyReals}, Vec3(v[0], v[1], v[2]), Vec3(v[19], v[20], v[21]),
                                               Vec3(v[22], v[23], v[24]), settings_))
      throw bad(problem);
    const Quat q(v[3], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-9) throw bad("has a quaternion that is not of unit length");
    const Mat3 expected = q.toRotationMatrix();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        if (std::abs(v[7 + 4 * r + c] - expected(r, c)) > 1e-9) throw bad("has a rotation matrix that is not its quaternion's");
  }
  seal();
  std::vector<Joint> run_time = loadJoints(in);
  checkJointWorlds(run_time, where);
  ensureThreadData();
  // the joints let go of their bodies, made again once the bodies are
  for (Joint& j : joints_) {
    if (j.id != nullptr) dJointDestroy(j.id);
    j.id = nullptr;
  }
  // the run-time joints the state has, in place of this engine's
  joints_.resize(scene_joints_);
  for (Joint& j : run_time) joints_.push_back(std::move(j));
  live_joints_ = 0;
  for (const Joint& j : joints_) live_joints_ += j.removed ? 0 : 1;
  repin(false);
  labels_stale_ = true;
  // every body created again in its saved world and order, so that ODE lists them as it did
  for (Partition& p : partitions_) p.order.clear();
  away_.clear();
  for (std::size_t p = 0; p < partitions_.size(); ++p) {
    partitions_[p].rand_seed = seeds[p];
    for (const int i : orders[p]) {
      Body& body = bodies_[static_cast<std::size_t>(i)];
      body.partition = static_cast<int>(p);  // (in no order list now: moveBody only appends it)
      moveBody(i, static_cast<int>(p));
      body.listed = body.home != static_cast<int>(p);
      if (body.listed) away_.push_back(i);
    }
  }
  remakeJoints(art_joints_);
  for (std::size_t i = 0; i < bodies_.size(); ++i) writeOdeBits(bodies_[i].id, values.data() + i * kOdeBodyReals);
}

}  // namespace ssx::detail
