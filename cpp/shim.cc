#include "dicephys/cpp/shim.h"

#include <BulletCollision/CollisionDispatch/btSimulationIslandManager.h>
#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <stdexcept>

#include "dicephys/src/engine/bullet.rs.h"

namespace dicephys {

namespace {
btVector3 vec(const std::array<double, 3>& a) { return btVector3(a[0], a[1], a[2]); }
std::array<double, 3> arr(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// Bullet's world, with two of a step's parts done without the work that changes nothing
// here (each the base class's code, less that work):
// - predictUnconstraintMotion damps each body, v *= pow(1 - d, dt), and predicts its
//   transform for the swept bounding box. With no damping (DicePhys's: d = 0) that is
//   v *= pow(1, dt) = 1 exactly, so it is left out there; a body with damping is damped as
//   Bullet does. The prediction is left out with the swept box (m_useContinuous, below).
// - createPredictiveContacts predicts every body's transform once more, to compare its
//   motion with the body's CCD threshold; but it acts on that only with m_useContinuous.
//   Without it, what is left is what the base class does whatever the motion.
class DiceWorld : public btDiscreteDynamicsWorld {
 public:
  using btDiscreteDynamicsWorld::btDiscreteDynamicsWorld;

 protected:
  // One dynamic body, not kinematic; every other object static; no joints, no predictive
  // contacts; islands split (Bullet's default).
  bool one_die() const {
    if (m_nonStaticRigidBodies.size() != 1 || m_nonStaticRigidBodies[0]->isKinematicObject() ||
        m_constraints.size() != 0 || m_predictiveManifolds.size() != 0 ||
        !m_islandManager->getSplitIslands()) {
      return false;
    }
    const btCollisionObjectArray& objects = getCollisionObjectArray();
    for (int i = 0; i < objects.size(); i++) {
      if (objects[i] != m_nonStaticRigidBodies[0] && !objects[i]->isStaticObject()) return false;
    }
    return true;
  }

  // A world of one die and static floors: the die's island is the die alone. Bullet finds
  // that every step with a union-find over every object and a sort of the manifolds by
  // island (btSimulationIslandManager), then hands the island to the solver. Here it is
  // done directly, with the same effects: each object's island tag, companion id and hit
  // fraction; the die put to sleep when it does not keep its island awake; and the same one
  // call to the solver, with the same bodies and manifolds (none while the island sleeps).
  // Any other world goes through Bullet's own.
  void calculateSimulationIslands() override {
    if (!one_die()) {
      btDiscreteDynamicsWorld::calculateSimulationIslands();
      return;
    }
    // btSimulationIslandManager::updateActivationState, then storeIslandActivationState.
    btCollisionObjectArray& objects = getCollisionObjectArray();
    for (int i = 0; i < objects.size(); i++) {
      btCollisionObject* o = objects[i];
      o->setHitFraction(btScalar(1.));
      const bool dynamic = !o->isStaticOrKinematicObject();
      o->setIslandTag(dynamic ? 0 : -1);
      o->setCompanionId(dynamic ? -1 : -2);
    }
  }

  void solveConstraints(btContactSolverInfo& info) override {
    if (!one_die() || info.m_minimumSolverBatchSize <= 1) {
      btDiscreteDynamicsWorld::solveConstraints(info);
      return;
    }
    btCollisionObject* die = m_nonStaticRigidBodies[0];
    btDispatcher* dispatcher = getDispatcher();
    m_constraintSolver->prepareSolve(getNumCollisionObjects(), dispatcher->getNumManifolds());
    // btSimulationIslandManager::buildIslands: an island none of whose bodies is active
    // (ACTIVE_TAG) or kept awake (DISABLE_DEACTIVATION) sleeps; then the manifolds with a
    // body awake and a contact response.
    const int state = die->getActivationState();
    if (state != ACTIVE_TAG && state != DISABLE_DEACTIVATION) {
      die->setActivationState(ISLAND_SLEEPING);
    }
    manifolds_.resize(0);
    for (int i = 0; i < dispatcher->getNumManifolds(); i++) {
      btPersistentManifold* m = dispatcher->getManifoldByIndexInternal(i);
      if (getDispatchInfo().m_deterministicOverlappingPairs && m->getNumContacts() == 0) continue;
      const btCollisionObject* a = m->getBody0();
      const btCollisionObject* b = m->getBody1();
      const bool awake = (a && a->getActivationState() != ISLAND_SLEEPING) ||
                         (b && b->getActivationState() != ISLAND_SLEEPING);
      if (awake && dispatcher->needsResponse(a, b)) manifolds_.push_back(m);
    }
    // processIslands hands a waking island to the callback, which defers it (batches of
    // m_minimumSolverBatchSize); solveConstraints then solves what was deferred, if anything.
    if (die->isActive()) {
      m_constraintSolver->solveGroup(&die, 1, manifolds_.size() ? &manifolds_[0] : nullptr,
                                     manifolds_.size(), nullptr, 0, info, getDebugDrawer(),
                                     dispatcher);
    } else {
      m_constraintSolver->solveGroup(nullptr, 0, nullptr, 0, nullptr, 0, info, getDebugDrawer(),
                                     dispatcher);
    }
    m_constraintSolver->allSolved(info, getDebugDrawer());
  }

  void createPredictiveContacts(btScalar dt) override {
    if (getDispatchInfo().m_useContinuous) {
      btDiscreteDynamicsWorld::createPredictiveContacts(dt);
      return;
    }
    releasePredictiveContacts();
    for (int i = 0; i < m_nonStaticRigidBodies.size(); i++) {
      m_nonStaticRigidBodies[i]->setHitFraction(1.f);
    }
  }

 private:
  btAlignedObjectArray<btPersistentManifold*> manifolds_;  // the die's island's, this step

  void predictUnconstraintMotion(btScalar dt) override {
    for (int i = 0; i < m_nonStaticRigidBodies.size(); i++) {
      btRigidBody* body = m_nonStaticRigidBodies[i];
      if (body->isStaticOrKinematicObject()) continue;
      // (We never turn on Bullet's "additional damping", which applyDamping also does.)
      if (body->getLinearDamping() != 0 || body->getAngularDamping() != 0) {
        body->applyDamping(dt);
      }
      if (getDispatchInfo().m_useContinuous) {
        body->predictIntegratedTransform(dt, body->getInterpolationWorldTransform());
      }
    }
  }
};
}  // namespace

BulletWorld::BulletWorld(const BulletScene& s)
    : dt_(s.dt),
      mass_(s.mass),
      die_friction_(s.die_friction),
      die_restitution_(s.die_restitution),
      planar_(s.planar),
      gyroscopic_(s.gyroscopic_implicit),
      deactivation_(s.deactivation),
      linear_damping_(s.linear_damping),
      angular_damping_(s.angular_damping) {
  config_ = std::make_unique<btDefaultCollisionConfiguration>();
  dispatcher_ = std::make_unique<btCollisionDispatcher>(config_.get());
  // Two bodies: the simplest broadphase does (the pair is the same; measured identical).
  broadphase_ = std::make_unique<btSimpleBroadphase>(4);
  solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
  if (s.stock_world) {
    world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), broadphase_.get(),
                                                       solver_.get(), config_.get());
  } else {
    world_ = std::make_unique<DiceWorld>(dispatcher_.get(), broadphase_.get(), solver_.get(),
                                         config_.get());
  }
  world_->setGravity(btVector3(0, -s.gravity, 0));
  // The floor never moves: do not recompute its bounding box every step.
  world_->setForceUpdateAllAabbs(false);
  // No swept bounding box: the die's box is its own, not grown to where it is predicted to be
  // at the step's end. What the box decides is whether the broadphase hands the pair to the
  // narrowphase, and the narrowphase tests the bodies where they are now: the box-box test
  // makes a point only where the boxes overlap, the convex-plane test within the breaking
  // threshold, which the box (grown by that threshold) covers. So no point is lost; a pair
  // dropped earlier holds no point (its points were dropped beyond the breaking threshold,
  // 1.4 mm, long before the boxes, grown by 2 cm, part). The prediction, a second transform
  // integrated per step, is then left out (DiceWorld). Measured: every roll identical
  // (scripts/prove-exact.sh).
  if (!s.stock_world) world_->getDispatchInfo().m_useContinuous = false;
  btContactSolverInfo& info = world_->getSolverInfo();
  info.m_splitImpulse = s.split_impulse ? 1 : 0;
  info.m_restitutionVelocityThreshold = s.restitution_velocity_threshold;
  info.m_numIterations = s.solver_iterations;

  // The floor: top face at y = 0. DicePhys's is a 10000 x 100 x 10000 m static box.
  btTransform floor_at;
  floor_at.setIdentity();
  if (s.plane_floor) {
    floor_shape_ = std::make_unique<btStaticPlaneShape>(btVector3(0, 1, 0), 0);
  } else {
    // 10 km square; 100 m thick as DicePhys's, or as thin as a table top.
    const double half = 0.5 * s.floor_thickness;
    floor_shape_ = std::make_unique<btBoxShape>(btVector3(5000., half, 5000.));
    floor_at.setOrigin(btVector3(0, -half, 0));
  }
  btRigidBody::btRigidBodyConstructionInfo floor_info(0.0, nullptr, floor_shape_.get());
  floor_info.m_startWorldTransform = floor_at;
  floor_info.m_friction = s.floor_friction;
  floor_info.m_restitution = s.floor_restitution;
  floor_ = std::make_unique<btRigidBody>(floor_info);
  world_->addRigidBody(floor_.get());

  die_shape_ = std::make_unique<btBoxShape>(
      btVector3(0.5 * s.sides[0], 0.5 * s.sides[1], 0.5 * s.sides[2]));
}

BulletWorld::~BulletWorld() {
  if (die_) world_->removeRigidBody(die_.get());
  if (floor_) world_->removeRigidBody(floor_.get());
}

// A throw starts from a new body, built as DicePhys builds it, so nothing of the previous
// roll (contact manifolds, solver caches, sleeping timers, forces) can leak into this one.
void BulletWorld::reset(const BodyStateFfi& start) {
  if (die_) {
    world_->removeRigidBody(die_.get());
    die_.reset();
  }
  btVector3 inertia(0, 0, 0);
  die_shape_->calculateLocalInertia(mass_, inertia);
  btRigidBody::btRigidBodyConstructionInfo info(mass_, nullptr, die_shape_.get(), inertia);
  btTransform at;
  at.setRotation(btQuaternion(start.rotation[0], start.rotation[1], start.rotation[2],
                              start.rotation[3]));
  at.setOrigin(vec(start.position));
  info.m_startWorldTransform = at;
  info.m_friction = die_friction_;
  info.m_restitution = die_restitution_;
  die_ = std::make_unique<btRigidBody>(info);
  // Bullet 2.83+ turns on implicit gyroscopic forces per body; 2.81 had none (flags 0).
  die_->setFlags(gyroscopic_ ? BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY : 0);
  die_->setLinearVelocity(vec(start.linear_velocity));
  die_->setAngularVelocity(vec(start.angular_velocity));
  if (planar_) {
    // DicePhys's 2D mode: motion locked to the x-y plane, rotation about z only.
    die_->setLinearFactor(btVector3(1, 1, 0));
    die_->setAngularFactor(btVector3(0, 0, 1));
  }
  if (!deactivation_) die_->setActivationState(DISABLE_DEACTIVATION);
  // DicePhys: none (0, 0), as a new body has. Bullet scales the velocities by (1 - d)^dt once a
  // step, before the contacts are solved.
  if (linear_damping_ != 0 || angular_damping_ != 0) {
    die_->setDamping(linear_damping_, angular_damping_);
  }
  world_->addRigidBody(die_.get());
}

// Moves the die to a state at the end of a stretch of free flight that Rust integrated in
// closed form exactly as Bullet would (flight.rs): started with no contact point held, and
// kept only while the die moves faster than Bullet's sleeping thresholds. So the body is left
// as such steps leave it: transform and velocities, the world inertia tensor for the new
// orientation (setCenterOfMassTransform), and the deactivation timer reset.
void BulletWorld::set_state(const BodyStateFfi& now) {
  if (!die_) throw std::logic_error("set_state before reset");
  btTransform at;
  at.setRotation(btQuaternion(now.rotation[0], now.rotation[1], now.rotation[2], now.rotation[3]));
  at.setOrigin(vec(now.position));
  die_->setLinearVelocity(vec(now.linear_velocity));
  die_->setAngularVelocity(vec(now.angular_velocity));
  // As a step ends (proceedToTransform), including the inverse inertia tensor in world axes,
  // which the solver uses at the next contact.
  die_->setCenterOfMassTransform(at);
  die_->setDeactivationTime(0);
  die_->setActivationState(ACTIVE_TAG);  // no effect under DISABLE_DEACTIVATION
}

// One fixed step per call, as DicePhys: stepSimulation(dt, 1, dt). Returns the state after
// it, so that a step and its read cross the FFI once.
BodyStateFfi BulletWorld::step() {
  if (!die_) throw std::logic_error("step before reset");
  world_->stepSimulation(dt_, 1, dt_);
  return state();
}

// The same n steps, each with its state read, without returning to Rust: used only to
// measure what crossing the FFI once per step costs.
void BulletWorld::step_n(std::uint32_t n) {
  if (!die_) throw std::logic_error("step before reset");
  volatile double sink = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    world_->stepSimulation(dt_, 1, dt_);
    const BodyStateFfi s = state();
    sink = sink + s.position[1] + s.rotation[3] + s.angular_velocity[2];
  }
}

BodyStateFfi BulletWorld::state() const {
  if (!die_) return BodyStateFfi{};
  BodyStateFfi out;  // every field set below: no zeroing first (this runs every step)
  const btTransform& t = die_->getWorldTransform();
  const btQuaternion q = t.getRotation();
  out.position = arr(t.getOrigin());
  out.rotation = {q.x(), q.y(), q.z(), q.w()};
  out.linear_velocity = arr(die_->getLinearVelocity());
  out.angular_velocity = arr(die_->getAngularVelocity());
  out.sleeping = die_->getActivationState() == ISLAND_SLEEPING;
  return out;
}

// Contact points kept in the world's manifolds (the die's with the floor): after a step, those
// found or kept on the state before it.
std::uint32_t BulletWorld::contact_points() const {
  std::uint32_t n = 0;
  for (int i = 0; i < dispatcher_->getNumManifolds(); ++i) {
    n += dispatcher_->getManifoldByIndexInternal(i)->getNumContacts();
  }
  return n;
}

std::unique_ptr<BulletWorld> new_world(const BulletScene& scene) {
  if (!(scene.dt > 0) || !(scene.mass > 0)) throw std::invalid_argument("bad scene");
  return std::make_unique<BulletWorld>(scene);
}

std::int32_t bullet_version() { return btGetVersion(); }

}  // namespace dicephys
