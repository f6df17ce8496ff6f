#include "engines/bullet/bullet_parts.hpp"
#include "engines/articulations.hpp"
#include "engines/state_checks.hpp"

#include <ssx/error.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

#include <Eigen/Eigenvalues>

namespace ssx::detail {

using namespace bullet;

namespace {

// a static mesh's triangles as Bullet reads them, kept beside the shape that reads them
struct MeshArrays {
  std::shared_ptr<const TriangleMesh> mesh;
  std::vector<int> indices;
  btTriangleIndexVertexArray array;
  explicit MeshArrays(std::shared_ptr<const TriangleMesh> m)
      : mesh(std::move(m)),
        indices(mesh->triangles.begin(), mesh->triangles.end()),
        array(static_cast<int>(indices.size() / 3), indices.data(), 3 * sizeof(int), static_cast<int>(mesh->vertices.size()),
              const_cast<btScalar*>(mesh->vertices.data()->data()), sizeof(Vec3)) {}
};

// (the arrays first: built before the shape, destroyed after it)
struct StaticMeshShape final : private MeshArrays, public btBvhTriangleMeshShape {
  explicit StaticMeshShape(std::shared_ptr<const TriangleMesh> m)
      : MeshArrays(std::move(m)), btBvhTriangleMeshShape(&array, true) {}
};

// the margin Bullet keeps around a hull (its default, 4 cm, is larger than a Crazyflie's arm)
constexpr double kHullMargin = 1e-3;

std::unique_ptr<btCollisionShape> createShape(const Shape& s, bool is_static) {
  switch (s.kind) {
    case Shape::Kind::Mesh: {
      if (is_static) return std::make_unique<StaticMeshShape>(s.mesh);
      const auto& v = s.mesh->hull_vertices;
      auto hull = std::make_unique<btConvexHullShape>(v.data()->data(), static_cast<int>(v.size()), sizeof(Vec3));
      hull->setMargin(kHullMargin);
      return hull;
    }
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
    case Shape::Kind::Mesh: return 2 * s.mesh->min.cwiseAbs().cwiseMax(s.mesh->max.cwiseAbs()).norm();
    case Shape::Kind::Plane: break;
  }
  return 0.0;
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

BulletEngine::BulletEngine(const PhysicsSettings& settings) : settings_(settings) {}

BulletEngine::~BulletEngine() = default;

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
    Geom g{createShape(s, false), {}, diameterOf(s)};
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
  body->mass = mass.mass;
  body->inertia = toBt(diagonal);
  body->rb->setFlags(BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY);
  body->rb->setActivationState(DISABLE_DEACTIVATION);
  body->rb->setGravity(toBt(settings_.gravity));
  body->rb->setUserIndex(index);
  // (a solver built thread-safe tells kinematic bodies apart by it: unique, as in a world)
  body->rb->setWorldArrayIndex(index);
  bodies_.push_back(std::move(body));
  proxies_stale_ = true;
  setState(index, state);
  return index;
}

void BulletEngine::setKinematic(int index) {
  Body& body = *bodies_.at(static_cast<std::size_t>(index));
  btRigidBody& rb = *body.rb;
  rb.setMassProps(0, btVector3(0, 0, 0));  // (also marks it static: Bullet's kinematic bodies are both)
  rb.setCollisionFlags(rb.getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  rb.updateInertiaTensor();
  body.kinematic = true;
  proxies_stale_ = true;
}

bool BulletEngine::isKinematic(int index) const { return bodies_.at(static_cast<std::size_t>(index))->kinematic; }

void BulletEngine::setEnabled(int index, bool enabled) {
  if (index < 0 || static_cast<std::size_t>(index) >= bodies_.size())
    throw Error("bullet: setEnabled: no body " + std::to_string(index));
  Body& body = *bodies_[static_cast<std::size_t>(index)];
  body.enabled = enabled;
  body.rb->clearForces();
}

void BulletEngine::setMassScale(int index, double mass_factor, double inertia_factor) {
  Body& body = *bodies_.at(static_cast<std::size_t>(index));
  if (body.kinematic) return;
  body.rb->setMassProps(body.mass * mass_factor, body.inertia * inertia_factor);
  body.rb->updateInertiaTensor();
}

int BulletEngine::addStatic(const std::vector<Shape>& shapes, const Pose& pose) {
  const int group = static_groups_++;
  for (const auto& s : shapes) {
    const Pose world = pose * s.pose;
    auto object = std::make_unique<StaticObject>();
    object->group = group;
    if (s.kind == Shape::Kind::Plane) {
      object->plane = true;
      object->normal = world.orientation * Vec3::UnitZ();
      object->offset = object->normal.dot(world.position);
      object->shape = std::make_unique<btStaticPlaneShape>(toBt(object->normal), object->offset);
    } else {
      object->shape = createShape(s, true);
    }
    object->object = std::make_unique<btCollisionObject>();
    object->object->setCollisionShape(object->shape.get());
    object->object->setUserIndex(-1);
    object->object->setUserIndex2(group);
    object->object->setFriction(settings_.friction);
    object->object->setRestitution(settings_.restitution);
    if (!object->plane)
      object->object->setWorldTransform(btTransform(toBt(world.orientation.normalized()), toBt(world.position)));
    if (object->plane) planes_.push_back(static_cast<int>(statics_.size()));
    statics_.push_back(std::move(object));
  }
  proxies_stale_ = true;
  return group;
}

void BulletEngine::solve(double h) {
  btContactSolverInfo info;
  const BulletSettings& b = settings_.bullet;
  info.m_timeStep = h;
  info.m_numIterations = b.iterations;
  info.m_erp2 = b.erp;
  info.m_erp = b.erp;  // joints
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
    context.solver.write_back = contact_log_.on();
    if (t < islands_.size()) {
      const Island& island = islands_[t];
      context.solver.solveGroup(&island_bodies_[island.first_body], static_cast<int>(island.bodies),
                                 island.manifolds == 0 ? nullptr : &island_manifolds_[island.first_manifold],
                                 static_cast<int>(island.manifolds),
                                 island.joints == 0 ? nullptr : &island_joints_[island.first_joint],
                                 static_cast<int>(island.joints), info, nullptr, &context.dispatcher);
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
  const bool log = contact_log_.on();
  if (log) contact_log_.begin();
  seal();
  if (labels_stale_ || articulation_.size() != bodies_.size()) {
    labelArticulations(articulation_, bodies_.size(), joints_);
    labelStaticParents(hangs_from_, articulation_, joints_);
    labels_stale_ = false;
  }
  if (live_joints_ > 0) setMotors(h);
  for (int s = 0; s < substeps; ++s) {
    // the held wrenches and gravity, every substep (the solver uses and the step clears them)
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
      btRigidBody& rb = *bodies_[i]->rb;
      rb.clearForces();
      if (!bodies_[i]->enabled) continue;  // out of the world: nothing moves it
      rb.applyCentralForce(toBt(wrenches[i].force));
      rb.applyTorque(toBt(wrenches[i].torque));
      rb.applyGravity();
    }
    collide(h);
    for (const btPersistentManifold* m : manifolds_) contact_count_ += static_cast<std::size_t>(m->getNumContacts());
    buildIslands();
    solve(h);
    if (log) logContacts();
    releaseContacts();
    forEach((bodies_.size() + kBodiesPerChunk - 1) / kBodiesPerChunk, [&](std::size_t c) {
      const std::size_t end = std::min(bodies_.size(), (c + 1) * kBodiesPerChunk);
      for (std::size_t i = c * kBodiesPerChunk; i < end; ++i) {
        if (!bodies_[i]->enabled) continue;
        btRigidBody& rb = *bodies_[i]->rb;
        btTransform next;
        rb.predictIntegratedTransform(h, next);
        rb.proceedToTransform(next);
        rb.clearForces();
      }
    });
  }
  if (log) contact_log_.finish();
}

void BulletEngine::logContacts() {
  // Bullet's normal on B points towards A; the applied impulse is the substep's, along it
  for (const btPersistentManifold* m : manifolds_) {
    const int a = m->getBody0()->getUserIndex(), b = m->getBody1()->getUserIndex();
    for (int k = 0; k < m->getNumContacts(); ++k) {
      const btManifoldPoint& p = m->getContactPoint(k);
      const btVector3& x = p.getPositionWorldOnB();
      const btVector3& n = p.m_normalWorldOnB;
      // (a static object's second user index is its group: addStatic)
      const int group = a < 0 ? m->getBody0()->getUserIndex2() : b < 0 ? m->getBody1()->getUserIndex2() : -1;
      contact_log_.add(a, b, group, Vec3(x.x(), x.y(), x.z()), Vec3(n.x(), n.y(), n.z()), -p.getDistance(),
                       p.getAppliedImpulse());
    }
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
  saveJoints(out);
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
  seal();
  std::vector<Joint> run_time = loadJoints(in);
  for (std::size_t i = 0; i < bodies_.size(); ++i) writeBits(*bodies_[i]->rb, values.data() + i * kBodyReals);
  // the run-time joints the state has, in place of this engine's (made from their saved frames)
  joints_.resize(scene_joints_);
  for (Joint& j : run_time) {
    if (!j.removed) makeConstraint(j);
    joints_.push_back(std::move(j));
  }
  live_joints_ = 0;
  for (const Joint& j : joints_) live_joints_ += j.removed ? 0 : 1;
  labels_stale_ = true;
}

}  // namespace ssx::detail
