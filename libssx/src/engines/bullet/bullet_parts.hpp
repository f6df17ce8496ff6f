#pragma once
// What bullet_engine.cpp and bullet_contacts.cpp share of the Bullet backend: the tuning constants,
// conversions, and the definitions of BulletEngine's private parts. Private to those two files.

#include "engines/bullet/bullet_engine.hpp"

#include <btBulletCollisionCommon.h>
#include <btBulletDynamicsCommon.h>

static_assert(sizeof(btScalar) == sizeof(double), "ssx uses Bullet in double precision (BT_USE_DOUBLE_PRECISION)");

namespace ssx::detail {

namespace bullet {
inline constexpr std::size_t kParallelFrom = 128;      // bodies: fewer are stepped on the caller's thread
inline constexpr std::size_t kBodiesPerChunk = 256;    // per task when posing geoms and integrating
inline constexpr std::size_t kGeomsPerPlaneChunk = 512;
inline constexpr std::size_t kFreeBodiesPerBatch = 256;  // bodies in no contact, per solveGroup call

inline btVector3 toBt(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
inline Vec3 fromBt(const btVector3& v) { return {v.x(), v.y(), v.z()}; }
inline btQuaternion toBt(const Quat& q) { return {q.x(), q.y(), q.z(), q.w()}; }
}  // namespace bullet

struct BulletEngine::Body {
  std::unique_ptr<btCompoundShape> compound;  // the body's shapes (its collision shape)
  std::unique_ptr<btRigidBody> rb;
  std::vector<Geom> geoms;
  Quat principal = Quat::Identity();  // Bullet's body frame in ssx's (the inertia's principal axes)
  bool rotated = false;               // principal is not the identity
  bool kinematic = false;             // moved only by setState (mass 0, CF_KINEMATIC_OBJECT)
  bool enabled = true;                // in the world (setEnabled): else nothing moves it, its boxes off
  double mass = 0;                    // as added (setMassScale scales these)
  btVector3 inertia{0, 0, 0};         // principal moments, as added
};

struct BulletEngine::StaticObject {
  std::unique_ptr<btCollisionShape> shape;
  std::unique_ptr<btCollisionObject> object;
  bool plane = false;
  Vec3 normal = Vec3::UnitZ();
  double offset = 0.0;  // plane: normal . x = offset
  int group = 0;        // addStatic's
};

// Bullet's solver, which also hands each contact point the impulse it applied when asked (Bullet
// writes them back only when warm starting, which would change nothing here: every substep's
// contacts are new)
class ImpulseSolver final : public btSequentialImpulseConstraintSolver {
 public:
  bool write_back = false;  // while the engine records contacts

 protected:
  btScalar solveGroupCacheFriendlyFinish(btCollisionObject** bodies, int count,
                                         const btContactSolverInfo& info) override {
    if (write_back && (info.m_solverMode & SOLVER_USE_WARMSTARTING) == 0)
      writeBackContacts(0, m_tmpSolverContactConstraintPool.size(), info);
    return btSequentialImpulseConstraintSolver::solveGroupCacheFriendlyFinish(bodies, count, info);
  }
};

struct BulletEngine::Context {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher;
  ImpulseSolver solver;
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
  if (runner_ == nullptr || runner_->threads() < 2 || bodies_.size() < bullet::kParallelFrom || n < 2) {
    for (std::size_t i = 0; i < n; ++i) task(i);
    return;
  }
  runner_->forEach(n, [](void* context, std::size_t i) { (*static_cast<F*>(context))(i); }, &task);
}

}  // namespace ssx::detail
