#include "bullet/bullet_engine.hpp"
#include "state_checks.hpp"

#include <ssx/error.hpp>

#include <btBulletCollisionCommon.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include <Eigen/Eigenvalues>

static_assert(sizeof(btScalar) == sizeof(double), "ssx uses Bullet in double precision (BT_USE_DOUBLE_PRECISION)");

namespace ssx::detail {

namespace {

constexpr std::size_t kParallelFrom = 128;      // bodies: fewer are stepped on the caller's thread
constexpr std::size_t kBodiesPerChunk = 256;    // per task when posing geoms and integrating
constexpr std::size_t kGeomsPerPlaneChunk = 512;
constexpr std::size_t kFreeBodiesPerBatch = 256;  // bodies in no contact, per solveGroup call

btVector3 toBt(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
Vec3 fromBt(const btVector3& v) { return {v.x(), v.y(), v.z()}; }
btQuaternion toBt(const Quat& q) { return {q.x(), q.y(), q.z(), q.w()}; }

std::unique_ptr<btCollisionShape> createShape(const Shape& s) {
  switch (s.kind) {
    case Shape::Kind::Box:
      return std::make_unique<btBoxShape>(toBt(s.size / 2));
    case Shape::Kind::Sphere:
      return std::make_unique<btSphereShape>(s.radius);
    case Shape::Kind::Cylinder:
      return std::make_unique<btCylinderShapeZ>(btVector3(s.radius, s.radius, s.length / 2));
    case Shape::Kind::Capsule:
      return std::make_unique<btCapsuleShapeZ>(s.radius, s.length);
    case Shape::Kind::Plane:
      break;
  }
  return nullptr;
}

double diameterOf(const Shape& s) {
  switch (s.kind) {
    case Shape::Kind::Box: return s.size.norm();
    case Shape::Kind::Sphere: return 2 * s.radius;
    case Shape::Kind::Cylinder: return 2 * std::hypot(s.radius, s.length / 2);
    case Shape::Kind::Capsule: return 2 * s.radius + s.length;
    case Shape::Kind::Plane: break;
  }
  return 0.0;
}

// the velocity of an object's material point at `world` (a static object: zero)
btVector3 velocityAt(const btCollisionObject* object, const btVector3& world) {
  const btRigidBody* rb = btRigidBody::upcast(object);
  if (rb == nullptr) return btVector3(0, 0, 0);
  return rb->getVelocityInLocalPoint(world - rb->getCenterOfMassPosition());
}

// A body's state bit for bit: the rotation matrix Bullet keeps (row by row), the origin, the
// linear and angular velocity
constexpr std::size_t kBodyReals = 9 + 3 + 3 + 3;

void readBits(const btRigidBody& rb, double* out) {
  const btTransform& t = rb.getCenterOfMassTransform();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[3 * r + c] = t.getBasis()[r][c];
  for (int k = 0; k < 3; ++k) {
    out[9 + k] = t.getOrigin()[k];
    out[12 + k] = rb.getLinearVelocity()[k];
    out[15 + k] = rb.getAngularVelocity()[k];
  }
}

void writeBits(btRigidBody& rb, const double* in) {
  btTransform t;
  t.getBasis().setValue(in[0], in[1], in[2], in[3], in[4], in[5], in[6], in[7], in[8]);
  t.setOrigin(btVector3(in[9], in[10], in[11]));
  rb.setCenterOfMassTransform(t);
  rb.setLinearVelocity(btVector3(in[12], in[13], in[14]));
  rb.setAngularVelocity(btVector3(in[15], in[16], in[17]));
}

}  // namespace

struct BulletEngine::Body {
  std::unique_ptr<btCompoundShape> compound;  // the body's shapes (its collision shape)
  std::unique_ptr<btRigidBody> rb;
  std::vector<Geom> geoms;
  Quat principal = Quat::Identity();  // Bullet's body frame in ssx's (the inertia's principal axes)
  bool rotated = false;               // principal is not the identity
};

struct BulletEngine::StaticObject {
  std::unique_ptr<btCollisionShape> shape;
  std::unique_ptr<btCollisionObject> object;
  bool plane = false;
  Vec3 normal = Vec3::UnitZ();
  double offset = 0.0;  // plane: normal . x = offset
};

struct BulletEngine::Context {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher;
  btSequentialImpulseConstraintSolver solver;
  Context() : dispatcher(&configuration) {
    // several contact points from one pass (the manifolds do not persist between substeps)
    configuration.setConvexConvexMultipointIterations();
    configuration.setPlaneConvexMultipointIterations();
    dispatcher.setDispatcherFlags(0);  // contacts up to gContactBreakingThreshold, whatever the shapes' size
  }
};

struct BulletEngine::ProxyPose {
  btTransform transform;
};

BulletEngine::BulletEngine(const PhysicsSettings& settings) : settings_(settings) {}

BulletEngine::~BulletEngine() = default;

// a context for one task: taken from the free ones (or made) and given back when the task ends
class BulletEngine::Lease {
 public:
  explicit Lease(BulletEngine& engine) : engine_(engine) {
    std::lock_guard lock(engine_.contexts_mutex_);
    if (engine_.free_contexts_.empty()) {
      engine_.contexts_.push_back(std::make_unique<Context>());
      context_ = engine_.contexts_.back().get();
    } else {
      context_ = engine_.free_contexts_.back();
      engine_.free_contexts_.pop_back();
    }
  }
  ~Lease() {
    std::lock_guard lock(engine_.contexts_mutex_);
    engine_.free_contexts_.push_back(context_);
  }
  Lease(const Lease&) = delete;
  Lease& operator=(const Lease&) = delete;
  Context& context() const { return *context_; }

 private:
  BulletEngine& engine_;
  Context* context_;
};

template <class F>
void BulletEngine::forEach(std::size_t n, F&& task) {
  if (runner_ == nullptr || runner_->threads() < 2 || bodies_.size() < kParallelFrom || n < 2) {
    for (std::size_t i = 0; i < n; ++i) task(i);
    return;
  }
  runner_->forEach(n, [](void* context, std::size_t i) { (*static_cast<F*>(context))(i); }, &task);
}

int BulletEngine::addBody(const MassProperties& mass, const std::vector<Shape>& shapes, const BodyState& state) {
  for (const auto& s : shapes)
    if (s.kind == Shape::Kind::Plane) throw Error("bullet: a plane cannot belong to a dynamic body");
  const int index = static_cast<int>(bodies_.size());
  auto body = std::make_unique<Body>();
  // Bullet's body frame has the inertia's principal axes; ssx's body frame is kept when the
  // inertia is diagonal in it (no rounding at all then)
  const Mat3& j = mass.inertia;
  Vec3 diagonal = j.diagonal();
  if (j(0, 1) != 0 || j(0, 2) != 0 || j(1, 2) != 0 || j(1, 0) != 0 || j(2, 0) != 0 || j(2, 1) != 0) {
    Eigen::SelfAdjointEigenSolver<Mat3> eigen(j);
    Mat3 axes = eigen.eigenvectors();
    if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
    diagonal = eigen.eigenvalues();
    body->principal = Quat(axes).normalized();
    body->rotated = true;
  }
  body->compound = std::make_unique<btCompoundShape>(false, static_cast<int>(shapes.size()));
  for (const auto& s : shapes) {
    Geom g{createShape(s), {}, diameterOf(s)};
    const Pose local{body->principal.conjugate() * s.pose.position, body->principal.conjugate() * s.pose.orientation};
    const Quat q = local.orientation.normalized();
    const double offset[7] = {local.position.x(), local.position.y(), local.position.z(), q.x(), q.y(), q.z(), q.w()};
    std::memcpy(g.offset, offset, sizeof offset);
    body->compound->addChildShape(btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), toBt(local.position)),
                                  g.shape.get());
    body->geoms.push_back(std::move(g));
  }
  btRigidBody::btRigidBodyConstructionInfo info(mass.mass, nullptr, body->compound.get(), toBt(diagonal));
  info.m_friction = settings_.friction;
  info.m_restitution = settings_.restitution;
  body->rb = std::make_unique<btRigidBody>(info);
  body->rb->setFlags(BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY);
  body->rb->setActivationState(DISABLE_DEACTIVATION);
  body->rb->setGravity(toBt(settings_.gravity));
  body->rb->setUserIndex(index);
  bodies_.push_back(std::move(body));
  proxies_stale_ = true;
  setState(index, state);
  return index;
}

void BulletEngine::addStatic(const std::vector<Shape>& shapes, const Pose& pose) {
  for (const auto& s : shapes) {
    const Pose world = pose * s.pose;
    auto object = std::make_unique<StaticObject>();
    if (s.kind == Shape::Kind::Plane) {
      object->plane = true;
      object->normal = world.orientation * Vec3::UnitZ();
      object->offset = object->normal.dot(world.position);
      object->shape = std::make_unique<btStaticPlaneShape>(toBt(object->normal), object->offset);
    } else {
      object->shape = createShape(s);
    }
    object->object = std::make_unique<btCollisionObject>();
    object->object->setCollisionShape(object->shape.get());
    object->object->setUserIndex(-1);
    object->object->setFriction(settings_.friction);
    object->object->setRestitution(settings_.restitution);
    if (!object->plane)
      object->object->setWorldTransform(btTransform(toBt(world.orientation.normalized()), toBt(world.position)));
    if (object->plane) planes_.push_back(static_cast<int>(statics_.size()));
    statics_.push_back(std::move(object));
  }
  proxies_stale_ = true;
}

void BulletEngine::indexGeoms() {
  proxies_stale_ = false;
  proxies_.clear();
  boxes_.clear();
  first_proxy_.assign(bodies_.size(), 0);
  std::vector<double> diameters;
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    first_proxy_[i] = static_cast<std::uint32_t>(proxies_.size());
    const Body& b = *bodies_[i];
    for (std::size_t k = 0; k < b.geoms.size(); ++k) {
      proxies_.push_back({b.rb.get(), b.geoms[k].shape.get(), static_cast<int>(i), static_cast<int>(k), -1});
      boxes_.push_back({Vec3::Zero(), Vec3::Zero(), static_cast<int>(i)});
      diameters.push_back(b.geoms[k].diameter);
    }
  }
  dynamic_proxies_ = proxies_.size();
  if (!diameters.empty()) {
    auto middle = diameters.begin() + static_cast<std::ptrdiff_t>(diameters.size() / 2);
    std::nth_element(diameters.begin(), middle, diameters.end());
    cell_ = std::max(2.0 * *middle, 1e-3);
  }
  const double margin = gContactBreakingThreshold / 2;
  for (std::size_t k = 0; k < statics_.size(); ++k) {
    const StaticObject& s = *statics_[k];
    if (s.plane) continue;
    btVector3 lo, hi;
    s.shape->getAabb(s.object->getWorldTransform(), lo, hi);
    proxies_.push_back({s.object.get(), s.shape.get(), -1, 0, static_cast<int>(k)});
    boxes_.push_back({fromBt(lo) - Vec3::Constant(margin), fromBt(hi) + Vec3::Constant(margin), -1});
  }
  poses_.resize(proxies_.size());
  for (std::size_t k = dynamic_proxies_; k < proxies_.size(); ++k)
    poses_[k].transform = proxies_[k].object->getWorldTransform();
  // room for what a substep usually needs, so that steps do not allocate: every body in contact
  // with a few others
  group_.assign(bodies_.size(), -1);
  touched_.reserve(bodies_.size());
  members_.reserve(bodies_.size());
  island_bodies_.reserve(bodies_.size());
  islands_.reserve(bodies_.size());
  free_bodies_.reserve(bodies_.size());
  manifolds_.reserve(4 * bodies_.size() + 64);
  island_manifolds_.reserve(4 * bodies_.size() + 64);
  manifold_order_.reserve(4 * bodies_.size() + 64);
}

void BulletEngine::placeGeoms(std::size_t begin, std::size_t end) {
  const double margin = gContactBreakingThreshold / 2;
  for (std::size_t i = begin; i < end; ++i) {
    const Body& body = *bodies_[i];
    const btTransform& t = body.rb->getCenterOfMassTransform();
    for (std::size_t k = 0; k < body.geoms.size(); ++k) {
      const Geom& g = body.geoms[k];
      const std::size_t p = first_proxy_[i] + k;
      const btTransform offset(btQuaternion(g.offset[3], g.offset[4], g.offset[5], g.offset[6]),
                               btVector3(g.offset[0], g.offset[1], g.offset[2]));
      poses_[p].transform = t * offset;
      btVector3 lo, hi;
      g.shape->getAabb(poses_[p].transform, lo, hi);
      boxes_[p].min = fromBt(lo) - Vec3::Constant(margin);
      boxes_[p].max = fromBt(hi) + Vec3::Constant(margin);
    }
  }
}

void BulletEngine::narrowphase(Context& context, Chunk& chunk, int a, int b, double h) {
  // a: a proxy; b: a proxy, or -1 - plane index for a plane
  if (b >= 0 && proxies_[static_cast<std::size_t>(a)].body < 0) std::swap(a, b);  // a body's geom first
  const Proxy& pa = proxies_[static_cast<std::size_t>(a)];
  const btCollisionObject* object_b;
  const btCollisionShape* shape_b;
  const btTransform* pose_b;
  int part_b = 0;
  if (b < 0) {
    const StaticObject& plane = *statics_[static_cast<std::size_t>(planes_[static_cast<std::size_t>(-1 - b)])];
    object_b = plane.object.get();
    shape_b = plane.shape.get();
    pose_b = &plane.object->getWorldTransform();
  } else {
    const Proxy& pb = proxies_[static_cast<std::size_t>(b)];
    object_b = pb.object;
    shape_b = pb.shape;
    pose_b = &poses_[static_cast<std::size_t>(b)].transform;
    part_b = pb.part;
  }
  const btCollisionObjectWrapper wa(nullptr, pa.shape, pa.object, poses_[static_cast<std::size_t>(a)].transform, -1,
                                    pa.part);
  const btCollisionObjectWrapper wb(nullptr, shape_b, object_b, *pose_b, -1, part_b);
  // a new algorithm, with a new manifold of its own (Bullet's algorithms make their own): the
  // contacts of this substep only; both live until the substep is solved
  btCollisionAlgorithm* algorithm = context.dispatcher.findAlgorithm(&wa, &wb, nullptr, BT_CONTACT_POINT_ALGORITHMS);
  if (algorithm == nullptr) return;
  chunk.algorithms.push_back({algorithm, &context});
  btManifoldResult result(&wa, &wb);
  btDispatcherInfo info;
  info.m_timeStep = h;
  info.m_useContinuous = false;
  algorithm->processCollision(&wa, &wb, info, &result);
  btManifoldArray& found = *chunk.found;
  found.resize(0);
  algorithm->getAllContactManifolds(found);
  for (int m = 0; m < found.size(); ++m) {
    btPersistentManifold* manifold = found[m];
    // Bullet reports points up to 2 cm apart, which its solver uses speculatively: it lets the gap
    // close and no more. A body that would reach the surface within this substep is thereby
    // stopped at it, a substep before the impact, so it never bounces (restitution is lost). Such
    // a point is made a touching one: the impact, with its restitution, happens now, less than one
    // substep's travel early. Points the body does not reach within the substep stay speculative.
    const int n = manifold->getNumContacts();
    if (n == 0) continue;
    for (int k = 0; k < n; ++k) {
      btManifoldPoint& p = manifold->getContactPoint(k);
      bool touching = p.getDistance() <= 0;
      if (!touching) {
        const btVector3 closing = velocityAt(manifold->getBody1(), p.getPositionWorldOnB()) -
                                  velocityAt(manifold->getBody0(), p.getPositionWorldOnA());
        touching = closing.dot(p.m_normalWorldOnB) * h >= p.getDistance();
        if (touching) p.setDistance(0);
      }
      p.m_combinedFriction = settings_.friction;
      p.m_combinedRestitution = touching ? settings_.restitution : 0.0;  // (a speculative point only stops)
      p.m_combinedRollingFriction = 0;
      p.m_combinedSpinningFriction = 0;
    }
    chunk.manifolds.push_back(manifold);
  }
}

void BulletEngine::releaseContacts() {
  // each algorithm back to the dispatcher that made it (its manifold with it), one at a time: a
  // dispatcher's pools are not shared between threads
  for (Chunk& chunk : chunks_) {
    for (const auto& [algorithm, context] : chunk.algorithms) {
      algorithm->~btCollisionAlgorithm();
      context->dispatcher.freeCollisionAlgorithm(algorithm);
    }
    chunk.algorithms.clear();
    chunk.manifolds.clear();
  }
}

void BulletEngine::collide(double h) {
  if (proxies_stale_) indexGeoms();
  forEach((bodies_.size() + kBodiesPerChunk - 1) / kBodiesPerChunk, [&](std::size_t c) {
    placeGeoms(c * kBodiesPerChunk, std::min(bodies_.size(), (c + 1) * kBodiesPerChunk));
  });
  grid_.build(boxes_, cell_);
  const std::size_t grid_chunks = grid_.chunkCount();
  const std::size_t plane_chunks =
      planes_.empty() ? 0 : (dynamic_proxies_ + kGeomsPerPlaneChunk - 1) / kGeomsPerPlaneChunk;
  if (chunks_.size() < grid_chunks + plane_chunks) {
    const std::size_t had = chunks_.size();
    chunks_.resize(grid_chunks + plane_chunks);
    for (std::size_t c = had; c < chunks_.size(); ++c) {
      chunks_[c].pairs.reserve(256);
      chunks_[c].algorithms.reserve(c < plane_chunks ? kGeomsPerPlaneChunk : 256);
      chunks_[c].manifolds.reserve(c < plane_chunks ? kGeomsPerPlaneChunk : 256);
      chunks_[c].found = std::make_shared<btManifoldArray>();
      chunks_[c].found->reserve(4);
    }
  }
  const double threshold = gContactBreakingThreshold;
  forEach(grid_chunks + plane_chunks, [&](std::size_t c) {
    Chunk& chunk = chunks_[c];
    const Lease lease(*this);
    Context& context = lease.context();
    if (c < plane_chunks) {
      const std::size_t begin = c * kGeomsPerPlaneChunk;
      const std::size_t end = std::min(dynamic_proxies_, begin + kGeomsPerPlaneChunk);
      for (std::size_t k = begin; k < end; ++k) {
        const GridBroadphase::Box& box = boxes_[k];
        const Vec3 centre = (box.min + box.max) / 2;
        const Vec3 half = (box.max - box.min) / 2;
        for (std::size_t p = 0; p < planes_.size(); ++p) {
          const StaticObject& plane = *statics_[static_cast<std::size_t>(planes_[p])];
          const double gap = plane.normal.dot(centre) - plane.normal.cwiseAbs().dot(half) - plane.offset;
          if (gap > threshold) continue;
          narrowphase(context, chunk, static_cast<int>(k), -1 - static_cast<int>(p), h);
        }
      }
      return;
    }
    chunk.pairs.clear();
    grid_.pairs(c - plane_chunks, chunk.pairs);
    for (const auto& [a, b] : chunk.pairs) narrowphase(context, chunk, a, b, h);
  });
  manifolds_.clear();
  for (std::size_t c = 0; c < grid_chunks + plane_chunks; ++c)
    manifolds_.insert(manifolds_.end(), chunks_[c].manifolds.begin(), chunks_[c].manifolds.end());
}

void BulletEngine::buildIslands() {
  // union-find over the bodies that touch each other (the smallest index as the root)
  auto find = [&](int x) {
    if (group_[static_cast<std::size_t>(x)] < 0) {
      group_[static_cast<std::size_t>(x)] = x;
      touched_.push_back(x);
    }
    while (group_[static_cast<std::size_t>(x)] != x) {
      const int up = group_[static_cast<std::size_t>(group_[static_cast<std::size_t>(x)])];
      group_[static_cast<std::size_t>(x)] = up;
      x = up;
    }
    return x;
  };
  auto bodyOf = [](const btCollisionObject* o) { return o->getUserIndex(); };
  // a manifold's body: a dynamic one of its two objects (the other may be static)
  auto ownerOf = [&](const btPersistentManifold* m) {
    const int a = bodyOf(m->getBody0());
    return a >= 0 ? a : bodyOf(m->getBody1());
  };
  for (const btPersistentManifold* m : manifolds_) {
    const int a = bodyOf(m->getBody0());
    const int b = bodyOf(m->getBody1());
    const int ra = find(a >= 0 ? a : b);
    if (a >= 0 && b >= 0) {
      const int rb = find(b);
      if (ra != rb) group_[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
    }
  }
  // islands in the order of their lowest body; bodies ascending, manifolds in pair order
  std::vector<std::pair<int, int>>& members = members_;  // (root, body)
  members.clear();
  for (const int i : touched_) members.emplace_back(find(i), i);
  std::sort(members.begin(), members.end());
  islands_.clear();
  island_bodies_.clear();
  for (std::size_t k = 0; k < members.size(); ++k) {
    if (k == 0 || members[k].first != members[k - 1].first)
      islands_.push_back({members[k].first, island_bodies_.size(), 0, 0, 0});
    island_bodies_.push_back(bodies_[static_cast<std::size_t>(members[k].second)]->rb.get());
    ++islands_.back().bodies;
  }
  std::vector<std::pair<int, std::size_t>>& order = manifold_order_;  // (root, manifold index)
  order.clear();
  for (std::size_t k = 0; k < manifolds_.size(); ++k) order.emplace_back(find(ownerOf(manifolds_[k])), k);
  std::sort(order.begin(), order.end());
  island_manifolds_.clear();
  std::size_t island = 0;
  for (const auto& [root, k] : order) {
    while (islands_[island].root != root) ++island;
    if (islands_[island].manifolds == 0) islands_[island].first_manifold = island_manifolds_.size();
    island_manifolds_.push_back(manifolds_[k]);
    ++islands_[island].manifolds;
  }
  free_bodies_.clear();
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    if (group_[i] < 0) free_bodies_.push_back(bodies_[i]->rb.get());
  for (const int i : touched_) group_[static_cast<std::size_t>(i)] = -1;
  touched_.clear();
}

void BulletEngine::solve(double h) {
  btContactSolverInfo info;
  const BulletSettings& b = settings_.bullet;
  info.m_timeStep = h;
  info.m_numIterations = b.iterations;
  info.m_erp2 = b.erp;
  info.m_globalCfm = b.cfm;
  info.m_splitImpulse = b.split_impulse ? 1 : 0;
  info.m_splitImpulsePenetrationThreshold = b.split_impulse_threshold;
  info.m_linearSlop = b.linear_slop;
  info.m_restitutionVelocityThreshold = 0.01;  // m/s: slower impacts do not bounce (as ODE's bounce_vel)
  // no warm start (contacts are new each substep); two friction directions per contact point
  info.m_solverMode = SOLVER_USE_2_FRICTION_DIRECTIONS | SOLVER_SIMD;
  const std::size_t batches = (free_bodies_.size() + kFreeBodiesPerBatch - 1) / kFreeBodiesPerBatch;
  forEach(islands_.size() + batches, [&](std::size_t t) {
    const Lease lease(*this);
    Context& context = lease.context();
    if (t < islands_.size()) {
      const Island& island = islands_[t];
      context.solver.solveGroup(&island_bodies_[island.first_body], static_cast<int>(island.bodies),
                                 island.manifolds == 0 ? nullptr : &island_manifolds_[island.first_manifold],
                                 static_cast<int>(island.manifolds), nullptr, 0, info, nullptr, &context.dispatcher);
      return;
    }
    const std::size_t begin = (t - islands_.size()) * kFreeBodiesPerBatch;
    const std::size_t count = std::min(kFreeBodiesPerBatch, free_bodies_.size() - begin);
    context.solver.solveGroup(&free_bodies_[begin], static_cast<int>(count), nullptr, 0, nullptr, 0, info, nullptr,
                               &context.dispatcher);
  });
}

void BulletEngine::step(Nanoseconds dt, std::span<const Wrench> wrenches) {
  const int substeps = std::max(1, settings_.substeps);
  const double h = toSeconds(dt) / substeps;
  contact_count_ = 0;
  for (int s = 0; s < substeps; ++s) {
    // the held wrenches and gravity, every substep (the solver uses and the step clears them)
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
      btRigidBody& rb = *bodies_[i]->rb;
      rb.clearForces();
      rb.applyCentralForce(toBt(wrenches[i].force));
      rb.applyTorque(toBt(wrenches[i].torque));
      rb.applyGravity();
    }
    collide(h);
    for (const btPersistentManifold* m : manifolds_) contact_count_ += static_cast<std::size_t>(m->getNumContacts());
    buildIslands();
    solve(h);
    releaseContacts();
    forEach((bodies_.size() + kBodiesPerChunk - 1) / kBodiesPerChunk, [&](std::size_t c) {
      const std::size_t end = std::min(bodies_.size(), (c + 1) * kBodiesPerChunk);
      for (std::size_t i = c * kBodiesPerChunk; i < end; ++i) {
        btRigidBody& rb = *bodies_[i]->rb;
        btTransform next;
        rb.predictIntegratedTransform(h, next);
        rb.proceedToTransform(next);
        rb.clearForces();
      }
    });
  }
}

void BulletEngine::readStates(std::span<BodyState> out) const {
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const Body& body = *bodies_[i];
    const btTransform& t = body.rb->getCenterOfMassTransform();
    btQuaternion q;
    t.getBasis().getRotation(q);
    BodyState& s = out[i];
    s.pose.position = fromBt(t.getOrigin());
    s.pose.orientation = Quat(q.w(), q.x(), q.y(), q.z());
    if (body.rotated) s.pose.orientation = s.pose.orientation * body.principal.conjugate();
    s.linear_velocity = fromBt(body.rb->getLinearVelocity());
    s.angular_velocity = fromBt(body.rb->getAngularVelocity());
  }
}

void BulletEngine::setState(int index, const BodyState& s) {
  Body& body = *bodies_.at(static_cast<std::size_t>(index));
  Quat q = s.pose.orientation.normalized();
  if (body.rotated) q = (q * body.principal).normalized();
  body.rb->setCenterOfMassTransform(btTransform(toBt(q), toBt(s.pose.position)));
  body.rb->setLinearVelocity(toBt(s.linear_velocity));
  body.rb->setAngularVelocity(toBt(s.angular_velocity));
}

void BulletEngine::saveState(StateWriter& out) const {
  out.write(static_cast<std::uint64_t>(bodies_.size()));
  for (const auto& body : bodies_) {
    double bits[kBodyReals];
    readBits(*body->rb, bits);
    out.bytes(bits, sizeof bits);
  }
}

void BulletEngine::restoreState(StateReader& in) {
  // everything is read and checked before anything is changed
  const auto count = in.get<std::uint64_t>();
  if (count != bodies_.size())
    throw StateError("bullet: the saved state has " + std::to_string(count) + " bodies, this world " +
                     std::to_string(bodies_.size()));
  std::vector<double> values(bodies_.size() * kBodyReals);
  in.bytes(values.data(), values.size() * sizeof(double));
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const double* v = values.data() + i * kBodyReals;
    auto bad = [&](const std::string& what) {
      return StateError("bullet: body " + std::to_string(i) + " in the saved state " + what);
    };
    if (const char* problem = savedBodyProblem({v, kBodyReals}, Vec3(v[9], v[10], v[11]), Vec3(v[12], v[13], v[14]),
                                               Vec3(v[15], v[16], v[17]), settings_))
      throw bad(problem);
    Mat3 r;
    for (int row = 0; row < 3; ++row)
      for (int c = 0; c < 3; ++c) r(row, c) = v[3 * row + c];
    if ((r * r.transpose() - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-9 || r.determinant() < 0)
      throw bad("has a rotation matrix that is not a rotation");
  }
  for (std::size_t i = 0; i < bodies_.size(); ++i) writeBits(*bodies_[i]->rb, values.data() + i * kBodyReals);
}

}  // namespace ssx::detail
