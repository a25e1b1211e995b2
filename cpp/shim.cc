#include "dicephys/cpp/shim.h"

#include <BulletCollision/CollisionDispatch/btSimulationIslandManager.h>
#include <BulletCollision/CollisionShapes/btMultiSphereShape.h>
#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "dicephys/src/engine/bullet.rs.h"

namespace dicephys {

namespace {
btVector3 vec(const std::array<double, 3>& a) { return btVector3(a[0], a[1], a[2]); }
std::array<double, 3> arr(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// btRigidBody::computeGyroscopicImpulseImplicit_Body (one Newton step of implicit Euler on
// Euler's equations in body axes, I ω' + h ω' × I ω' = I ω), with the moments divided by the
// largest. Bullet's own solves J x = f with btMatrix3x3::solve33, which divides by det J
// only above DBL_EPSILON and otherwise multiplies by it: for a die (moments ~1e-7 kg m²,
// det J ~1e-21 kg³ m⁶) x comes out det² of itself, nothing, so that a die never precesses
// and a body with unequal moments does not keep its angular momentum in flight (measured in
// tests/it/impact.rs). J and f scale alike with the moments, so x is unchanged.
btVector3 gyroscopic_impulse(const btRigidBody& die, btScalar step) {
  btVector3 idl = die.getLocalInertia();
  idl /= btMax(idl.x(), btMax(idl.y(), idl.z()));
  const btVector3 omega1 = die.getAngularVelocity();
  const btQuaternion q = die.getWorldTransform().getRotation();
  btVector3 omegab = quatRotate(q.inverse(), omega1);
  btMatrix3x3 Ib;
  Ib.setValue(idl.x(), 0, 0, 0, idl.y(), 0, 0, 0, idl.z());
  const btVector3 ibo = Ib * omegab;
  const btVector3 f = step * omegab.cross(ibo);
  btMatrix3x3 skew0;
  omegab.getSkewSymmetricMatrix(&skew0[0], &skew0[1], &skew0[2]);
  btMatrix3x3 skew1;
  ibo.getSkewSymmetricMatrix(&skew1[0], &skew1[1], &skew1[2]);
  const btMatrix3x3 J = Ib + (skew0 * Ib - skew1) * step;
  omegab = omegab - J.solve33(f);
  return quatRotate(q, omegab) - omega1;
}

// Bullet's world, with two of a step's parts done without the work that changes nothing
// here (each the base class's code, less that work):
// - predictUnconstraintMotion damps each body, v *= pow(1 - d, dt), and predicts its
//   transform for the swept bounding box. With no damping (DicePhys's: d = 0) that is
//   v *= pow(1, dt) = 1 exactly, so it is left out there; a body with damping is damped as
//   Bullet does. The prediction is left out with the swept box (m_useContinuous, below).
//   Under `laws` it also adds the die's gyroscopic impulse (`gyroscopic_scaled`), which
//   Bullet's stock world (`stock_world`) does not.
// - createPredictiveContacts predicts every body's transform once more, to compare its
//   motion with the body's CCD threshold; but it acts on that only with m_useContinuous.
//   Without it, what is left is what the base class does whatever the motion.
class DiceWorld : public btDiscreteDynamicsWorld {
 public:
  using btDiscreteDynamicsWorld::btDiscreteDynamicsWorld;
  // The die turns as Euler's equations say: Bullet's implicit gyroscopic impulse at a scale
  // where its own arithmetic does not drop it (`gyroscopic_impulse`), added to the angular
  // velocity as each step starts, in flight and in contact, whichever solver runs.
  bool gyroscopic_scaled = false;

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
      // Where Bullet's convertBodies would add its own (from the velocity after damping).
      if (gyroscopic_scaled) {
        body->setAngularVelocity(body->getAngularVelocity() + gyroscopic_impulse(*body, dt));
      }
      if (getDispatchInfo().m_useContinuous) {
        body->predictIntegratedTransform(dt, body->getInterpolationWorldTransform());
      }
    }
  }
};

// Bullet's sequential-impulse solver, for one die on fixed bodies (floors) done without its
// generality: no pools of solver bodies and rows, no row solver behind a function pointer.
// The arithmetic is Bullet 3.24's, operation for operation, in the same order, on the die's
// side of each row. A fixed body's side of a row is zero (Bullet zeroes its normal, r x n and
// angular component), its velocity and velocity deltas are zero and never move, and applying
// an impulse to it does nothing; so what it adds to a sum is +0, kept where it is added
// (x + 0 turns -0 into +0) and left out where it is subtracted (x - (+0) = x):
// - convertContact, setupContactConstraint and setupFrictionConstraint set up each contact
//   point's two rows (a contact and one friction direction: Bullet's default mode);
// - the passes over the rows are gResolveSingleConstraintRow{LowerLimit,Generic} and
//   gResolveSplitPenetrationImpulse (the scalar reference, which double precision uses). The
//   floor's term there, (0 . 0 + 0 . 0) * J, is kept as computed (J could be anything);
// - the residual that stops the passes early is kept exactly;
// - the write-back (warm-starting impulses to the contact points; velocities, split-impulse
//   transform and companion id to the die) is solveGroupCacheFriendlyFinish's.
// Any other world (joints, two moving bodies, a kinematic body), solver mode, or contact
// (its own CFM/ERP, stiffness, friction anchors, rolling or anisotropic friction) goes through
// Bullet's own solveGroup; under two friction directions (`laws`) with its passes replaced by
// one that holds each point's friction to Coulomb's law (solveSingleIteration, below).
class DieSolver : public btSequentialImpulseConstraintSolver {
 public:
  // Static friction over sliding friction (`Scene::static_ratio`; 1: one friction, as Bullet)
  // and the slip, m/s, below which a point counts as not sliding (`Scene::stick_speed`).
  btScalar static_ratio = 1;
  btScalar stick_speed = 0;

  btScalar solveGroup(btCollisionObject** bodies, int numBodies, btPersistentManifold** manifolds,
                      int numManifolds, btTypedConstraint** constraints, int numConstraints,
                      const btContactSolverInfo& info, btIDebugDraw* debugDrawer,
                      btDispatcher* dispatcher) override {
    if (static_ratio != 1) hold(manifolds, numManifolds);
    btRigidBody* die = numBodies == 1 ? btRigidBody::upcast(bodies[0]) : nullptr;
    if (numConstraints != 0 || !die || !fits(die, manifolds, numManifolds, info)) {
      return btSequentialImpulseConstraintSolver::solveGroup(bodies, numBodies, manifolds,
                                                             numManifolds, constraints,
                                                             numConstraints, info, debugDrawer,
                                                             dispatcher);
    }
    setup(die, manifolds, numManifolds, info);
    iterate(info, numManifolds);
    finish(die, info);
    return 0.f;
  }

 protected:
  // Under `laws` (two friction rows per point) one pass of Bullet's own solver, with each
  // point's friction held to Coulomb's cone. Bullet clamps each of the two rows to μ times the
  // point's normal impulse on its own: a square, whose corners reach √2 μ, and a sliding
  // corner's friction 14 % beyond the cone and 28° off its slip (tests/it/impact.rs). Here
  // a point's two rows are solved together (`coulomb`, below): in the disc of radius μ times
  // the normal impulse, and on its rim against the slip. Any other solver mode, or a world
  // with joints, is Bullet's own pass.
  btScalar solveSingleIteration(int iteration, btCollisionObject** bodies, int numBodies,
                                btPersistentManifold** manifoldPtr, int numManifolds,
                                btTypedConstraint** constraints, int numConstraints,
                                const btContactSolverInfo& info,
                                btIDebugDraw* debugDrawer) override {
    const int others = SOLVER_RANDMIZE_ORDER | SOLVER_INTERLEAVE_CONTACT_AND_FRICTION_CONSTRAINTS;
    if (!(info.m_solverMode & SOLVER_USE_2_FRICTION_DIRECTIONS) || (info.m_solverMode & others) ||
        numConstraints != 0 || m_tmpSolverNonContactConstraintPool.size() != 0) {
      return btSequentialImpulseConstraintSolver::solveSingleIteration(
          iteration, bodies, numBodies, manifoldPtr, numManifolds, constraints, numConstraints,
          info, debugDrawer);
    }
    btScalar residual = 0.f;
    if (iteration >= info.m_numIterations) return residual;
    const auto solve = [&](btSingleConstraintRowSolver row, btSolverConstraint& c) {
      const btScalar r = row(m_tmpSolverBodyPool[c.m_solverBodyIdA],
                             m_tmpSolverBodyPool[c.m_solverBodyIdB], c);
      residual = btMax(residual, r * r);
    };
    for (int j = 0; j < m_tmpSolverContactConstraintPool.size(); j++) {
      solve(m_resolveSingleConstraintRowLowerLimit,
            m_tmpSolverContactConstraintPool[m_orderTmpConstraintPool[j]]);
    }
    // The friction pool holds each point's two rows side by side (convertContact).
    const int rows = m_tmpSolverContactFrictionConstraintPool.size();
    for (int j = 0; j < rows;) {
      btSolverConstraint& a = m_tmpSolverContactFrictionConstraintPool[j];
      const btScalar total = m_tmpSolverContactConstraintPool[a.m_frictionIndex].m_appliedImpulse;
      if (j + 1 < rows &&
          m_tmpSolverContactFrictionConstraintPool[j + 1].m_frictionIndex == a.m_frictionIndex) {
        if (total > btScalar(0)) {
          residual = btMax(residual, coulomb(a, m_tmpSolverContactFrictionConstraintPool[j + 1],
                                             a.m_friction * total));
        }
        j += 2;
        continue;
      }
      if (total > btScalar(0)) {
        a.m_lowerLimit = -(a.m_friction * total);
        a.m_upperLimit = a.m_friction * total;
        solve(m_resolveSingleConstraintRowGeneric, a);
      }
      j += 1;
    }
    for (int j = 0; j < m_tmpSolverContactRollingFrictionConstraintPool.size(); j++) {
      btSolverConstraint& c = m_tmpSolverContactRollingFrictionConstraintPool[j];
      const btScalar total = m_tmpSolverContactConstraintPool[c.m_frictionIndex].m_appliedImpulse;
      if (total > btScalar(0)) {
        const btScalar most = btMin(c.m_friction * total, c.m_friction);
        c.m_lowerLimit = -most;
        c.m_upperLimit = most;
        solve(m_resolveSingleConstraintRowGeneric, c);
      }
    }
    return residual;
  }

 private:
  // Static against sliding friction. Each point's friction, before any row is set up from it,
  // is the pair's sliding friction (Bullet's product of the two bodies' frictions), times
  // static_ratio where the point does not slide as the step begins: its two bodies'
  // velocities there (as the last step left them; gravity's impulse, added in the solve, is
  // along the floor's normal) differ along the contact's plane by no more than stick_speed.
  // A point that held through the last step ends it slipping by the solver's residual only;
  // one whose grip gives way slides at static friction until its slip passes stick_speed
  // (g dt: a few steps), then at sliding friction. Every point is set every step, so a point
  // kept from an earlier step carries no stale value.
  void hold(btPersistentManifold** manifolds, int numManifolds) const {
    for (int i = 0; i < numManifolds; i++) {
      btPersistentManifold* m = manifolds[i];
      const btCollisionObject* a = m->getBody0();
      const btCollisionObject* b = m->getBody1();
      const btScalar sliding = btManifoldResult::calculateCombinedFriction(a, b);
      const btScalar holding = btMin(sliding * static_ratio, btScalar(10));
      const btRigidBody* ra = btRigidBody::upcast(a);
      const btRigidBody* rb = btRigidBody::upcast(b);
      for (int j = 0; j < m->getNumContacts(); j++) {
        btManifoldPoint& cp = m->getContactPoint(j);
        btVector3 v(0, 0, 0);
        if (ra) {
          v += ra->getVelocityInLocalPoint(cp.getPositionWorldOnA() -
                                           a->getWorldTransform().getOrigin());
        }
        if (rb) {
          v -= rb->getVelocityInLocalPoint(cp.getPositionWorldOnB() -
                                           b->getWorldTransform().getOrigin());
        }
        const btVector3 slip = v - cp.m_normalWorldOnB * cp.m_normalWorldOnB.dot(v);
        cp.m_combinedFriction =
            slip.length2() <= stick_speed * stick_speed ? holding : sliding;
      }
    }
  }

  // One row, the die's side of it: its normal and r x n, and what an impulse along it does
  // to the die (n times the inverse mass, and the angular component).
  struct Row {
    btVector3 normal, torque_axis, linear, angular;
    btScalar jac_diag_inv, rhs, rhs_penetration, cfm, lower, upper, friction;
    btScalar applied, applied_push;
    bool die_is_a;             // the die is the row's body A (else B; the floor is the other)
    int contact;               // a friction row's contact row
    btManifoldPoint* point;    // a contact row's point
  };
  // Grown, never shrunk: a step's rows are the first contact_rows_ (friction_rows_).
  std::vector<Row> contacts_, frictions_;
  int contact_rows_ = 0, friction_rows_ = 0;
  btVector3 delta_linear_, delta_angular_, push_, turn_, linear_factor_, angular_factor_;

  static constexpr int kDie = 0;  // the die's solver body
  static btScalar square(btScalar x) { return x * x; }

  // The velocity along row `i` that a unit impulse along row `j` adds, through `body`
  // (internalApplyImpulse; a fixed body takes none).
  static btScalar response(const btSolverBody& body, const btVector3& ni, const btVector3& ci,
                           const btVector3& nj, const btVector3& aj) {
    if (!body.m_originalBody) return 0;
    return ni.dot(nj * body.internalGetInvMass() * body.m_linearFactor) +
           ci.dot(aj * body.m_angularFactor);
  }

  // One point's friction, its two rows `a` and `b` solved together to Coulomb's law with the
  // rest of the world held: f in the disc |f| <= cap, and where it is on the rim, against the
  // point's slip as it ends (maximal dissipation). With u = w + K f the point's slip (K its
  // 2x2 inverse mass along the rows): the impulse that stops it, -K^-1 w, if it lies in the
  // disc; else the fixed point of f <- proj(f - u/k), k = K's largest eigenvalue, which
  // lies on the rim with u along -f (the arbiter's step, src/engine/moreau.rs, here iterated
  // to convergence for the one point). Returns the squared change, as a row's residual.
  btScalar coulomb(btSolverConstraint& a, btSolverConstraint& b, btScalar cap) {
    btSolverBody& A = m_tmpSolverBodyPool[a.m_solverBodyIdA];
    btSolverBody& B = m_tmpSolverBodyPool[a.m_solverBodyIdB];
    const btSolverConstraint* row[2] = {&a, &b};
    btScalar K[2][2], u[2], f0[2] = {a.m_appliedImpulse, b.m_appliedImpulse};
    for (int i = 0; i < 2; i++) {
      const btSolverConstraint& ri = *row[i];
      for (int j = 0; j < 2; j++) {
        const btSolverConstraint& rj = *row[j];
        K[i][j] = response(A, ri.m_contactNormal1, ri.m_relpos1CrossNormal, rj.m_contactNormal1,
                           rj.m_angularComponentA) +
                  response(B, ri.m_contactNormal2, ri.m_relpos2CrossNormal, rj.m_contactNormal2,
                           rj.m_angularComponentB);
      }
      // The row's velocity now: as the step began (its right-hand side over its gain, as
      // Bullet's row solver reads it) plus what the impulses so far added.
      const btScalar added =
          ri.m_contactNormal1.dot(A.internalGetDeltaLinearVelocity()) +
          ri.m_relpos1CrossNormal.dot(A.internalGetDeltaAngularVelocity()) +
          ri.m_contactNormal2.dot(B.internalGetDeltaLinearVelocity()) +
          ri.m_relpos2CrossNormal.dot(B.internalGetDeltaAngularVelocity());
      u[i] = -ri.m_rhs / ri.m_jacDiagABInv + added;
    }
    // w: the slip with this point's friction taken away.
    const btScalar w[2] = {u[0] - K[0][0] * f0[0] - K[0][1] * f0[1],
                           u[1] - K[1][0] * f0[0] - K[1][1] * f0[1]};
    const btScalar det = K[0][0] * K[1][1] - K[0][1] * K[1][0];
    btScalar f[2] = {-(K[1][1] * w[0] - K[0][1] * w[1]) / det,
                     -(K[0][0] * w[1] - K[1][0] * w[0]) / det};
    if (!(btSqrt(square(f[0]) + square(f[1])) <= cap)) {
      const btScalar half = 0.5 * (K[0][0] + K[1][1]);
      const btScalar largest =
          half + btSqrt(0.25 * square(K[0][0] - K[1][1]) + K[0][1] * K[1][0]);
      f[0] = f0[0];
      f[1] = f0[1];
      for (int it = 0; it < 200; it++) {
        btScalar g[2] = {f[0] - (w[0] + K[0][0] * f[0] + K[0][1] * f[1]) / largest,
                         f[1] - (w[1] + K[1][0] * f[0] + K[1][1] * f[1]) / largest};
        const btScalar norm = btSqrt(square(g[0]) + square(g[1]));
        if (norm > cap) {
          g[0] *= cap / norm;
          g[1] *= cap / norm;
        }
        const btScalar change = square(g[0] - f[0]) + square(g[1] - f[1]);
        f[0] = g[0];
        f[1] = g[1];
        if (change <= square(1e-12 * cap)) break;
      }
    }
    btScalar residual = 0;
    for (int i = 0; i < 2; i++) {
      btSolverConstraint& c = i == 0 ? a : b;
      const btScalar delta = f[i] - f0[i];
      c.m_appliedImpulse = f[i];
      A.internalApplyImpulse(c.m_contactNormal1 * A.internalGetInvMass(), c.m_angularComponentA,
                             delta);
      B.internalApplyImpulse(c.m_contactNormal2 * B.internalGetInvMass(), c.m_angularComponentB,
                             delta);
      residual = btMax(residual, square(delta / c.m_jacDiagABInv));
    }
    return residual;
  }

  // Whether Bullet's solveGroup would treat this as the one die this class solves.
  bool fits(btRigidBody* die, btPersistentManifold** manifolds, int numManifolds,
            const btContactSolverInfo& info) const {
#ifdef USE_SIMD
    return false;  // Bullet's SIMD row solvers (single precision only) are not these
#endif
    const int unsupported = SOLVER_RANDMIZE_ORDER | SOLVER_USE_2_FRICTION_DIRECTIONS |
                            SOLVER_ENABLE_FRICTION_DIRECTION_CACHING |
                            SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION |
                            SOLVER_INTERLEAVE_CONTACT_AND_FRICTION_CONSTRAINTS;
    if ((info.m_solverMode & unsupported) || die->getInvMass() == 0 ||
        die->isKinematicObject() || die->hasAnisotropicFriction() ||
        (die->getFlags() &
         (BT_ENABLE_GYROSCOPIC_FORCE_EXPLICIT | BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_WORLD))) {
      return false;
    }
    const int own = BT_CONTACT_FLAG_HAS_CONTACT_CFM | BT_CONTACT_FLAG_HAS_CONTACT_ERP |
                    BT_CONTACT_FLAG_CONTACT_STIFFNESS_DAMPING | BT_CONTACT_FLAG_FRICTION_ANCHOR;
    for (int i = 0; i < numManifolds; i++) {
      const btPersistentManifold* m = manifolds[i];
      const btCollisionObject* other = m->getBody0() == die ? m->getBody1() : m->getBody0();
      if (m->getBody0() != die && m->getBody1() != die) return false;
      // Bullet's getOrInitSolverBody makes it the fixed body only so.
      const btRigidBody* rb = btRigidBody::upcast(other);
      if (other == die || other->getCompanionId() >= 0 || other->hasAnisotropicFriction() ||
          (rb && (rb->getInvMass() != 0 || rb->isKinematicObject()))) {
        return false;
      }
      for (int j = 0; j < m->getNumContacts(); j++) {
        const btManifoldPoint& cp = m->getContactPoint(j);
        if ((cp.m_contactPointFlags & own) || cp.m_combinedRollingFriction > 0.f) return false;
      }
    }
    return true;
  }

  // solveGroupCacheFriendlySetup: convertBodies, then convertContacts.
  void setup(btRigidBody* die, btPersistentManifold** manifolds, int numManifolds,
             const btContactSolverInfo& info) {
    if (info.m_solverMode != m_cachedSolverMode) {
      setupSolverFunctions(!!(info.m_solverMode & SOLVER_SIMD));
      m_cachedSolverMode = info.m_solverMode;
    }
    m_maxOverrideNumSolverIterations = 0;
    // convertBodies: the die's solver body, then its gyroscopic impulse.
    if (m_tmpSolverBodyPool.size() < 1) m_tmpSolverBodyPool.resize(1);
    btSolverBody& body = m_tmpSolverBodyPool[kDie];
    initSolverBody(&body, die, info.m_timeStep);
    die->setCompanionId(kDie);
    if (die->getFlags() & BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY) {
      body.m_externalTorqueImpulse += die->computeGyroscopicImpulseImplicit_Body(info.m_timeStep);
    }
    delta_linear_ = body.m_deltaLinearVelocity;
    delta_angular_ = body.m_deltaAngularVelocity;
    push_ = body.m_pushVelocity;
    turn_ = body.m_turnVelocity;
    linear_factor_ = body.m_linearFactor;
    angular_factor_ = body.m_angularFactor;
    contact_rows_ = 0;
    friction_rows_ = 0;
    for (int i = 0; i < numManifolds; i++) convert_contact(manifolds[i], die, info);
  }

  // convertContact, for a manifold between the die and a fixed body: a contact row and one
  // friction row per point within the processing threshold.
  void convert_contact(btPersistentManifold* manifold, btRigidBody* die,
                       const btContactSolverInfo& info) {
    btCollisionObject* colObj0 = (btCollisionObject*)manifold->getBody0();
    btCollisionObject* colObj1 = (btCollisionObject*)manifold->getBody1();
    const bool die_is_a = colObj0 == die;
    const btSolverBody& body = m_tmpSolverBodyPool[kDie];
    // (The fixed body's inverse mass is zero.)
    if (body.m_invMass.fuzzyZero()) return;
    const btVector3 zero(0, 0, 0);  // the fixed body's velocity, and its side of each row
    for (int j = 0; j < manifold->getNumContacts(); j++) {
      btManifoldPoint& cp = manifold->getContactPoint(j);
      if (!(cp.getDistance() <= manifold->getContactProcessingThreshold())) continue;
      const btVector3 rel_pos1 = cp.getPositionWorldOnA() - colObj0->getWorldTransform().getOrigin();
      const btVector3 rel_pos2 = cp.getPositionWorldOnB() - colObj1->getWorldTransform().getOrigin();
      const btVector3& rel_pos = die_is_a ? rel_pos1 : rel_pos2;  // the die's
      // getVelocityInLocalPointNoDelta of each body (the fixed body's is zero).
      const btVector3 die_vel = body.m_linearVelocity + body.m_externalForceImpulse +
                                (body.m_angularVelocity + body.m_externalTorqueImpulse).cross(rel_pos);
      const btVector3 vel = die_is_a ? die_vel - zero : zero - die_vel;
      const btScalar rel_vel = cp.m_normalWorldOnB.dot(vel);
      const btScalar relaxation = info.m_sor;
      const int contact = contact_row(cp, die, die_is_a, rel_pos, info);
      contacts_[contact].point = &cp;
      // The friction direction: along the sliding velocity, or any if there is none.
      cp.m_lateralFrictionDir1 = vel - cp.m_normalWorldOnB * rel_vel;
      const btScalar lat_rel_vel = cp.m_lateralFrictionDir1.length2();
      if (lat_rel_vel > SIMD_EPSILON) {
        cp.m_lateralFrictionDir1 *= 1.f / btSqrt(lat_rel_vel);
      } else {
        btPlaneSpace1(cp.m_normalWorldOnB, cp.m_lateralFrictionDir1, cp.m_lateralFrictionDir2);
      }
      const int friction =
          friction_row(cp, cp.m_lateralFrictionDir1, die, die_is_a, rel_pos, relaxation);
      frictions_[friction].contact = contact;
    }
  }

  Row& new_row(std::vector<Row>& rows, int& used) {
    if (rows.size() <= std::size_t(used)) rows.resize(used + 1);
    return rows[used++];
  }

  // setupContactConstraint, the die's side; the fixed body's side is zero (its normal, r x n
  // and angular component), its velocity zero, and no impulse is applied to it. Each value
  // is computed as Bullet computes it, the fixed body's zero terms included where they
  // are added (x + 0 turns -0 into +0).
  int contact_row(btManifoldPoint& cp, btRigidBody* die, bool die_is_a, const btVector3& rel_pos,
                  const btContactSolverInfo& info) {
    const btVector3& n = cp.m_normalWorldOnB;
    const btScalar relaxation = info.m_sor;
    const btScalar invTimeStep = btScalar(1) / info.m_timeStep;
    btScalar cfm = info.m_globalCfm;
    const btScalar erp = info.m_erp2;
    cfm *= invTimeStep;
    Row& r = new_row(contacts_, contact_rows_);
    r.die_is_a = die_is_a;
    const btVector3 torqueAxis = rel_pos.cross(n);
    btScalar denom;
    if (die_is_a) {
      r.angular = die->getInvInertiaTensorWorld() * torqueAxis * die->getAngularFactor();
      const btScalar denom0 = die->getInvMass() + n.dot(r.angular.cross(rel_pos));
      denom = relaxation / (denom0 + btScalar(0) + cfm);
      r.normal = n;
      r.torque_axis = torqueAxis;
    } else {
      r.angular = die->getInvInertiaTensorWorld() * -torqueAxis * die->getAngularFactor();
      const btScalar denom1 = die->getInvMass() + n.dot((-r.angular).cross(rel_pos));
      denom = relaxation / (btScalar(0) + denom1 + cfm);
      r.normal = -n;
      r.torque_axis = -torqueAxis;
    }
    r.jac_diag_inv = denom;
    const btSolverBody& body = m_tmpSolverBodyPool[kDie];
    r.linear = r.normal * body.internalGetInvMass();
    btScalar restitution = 0.f;
    const btScalar penetration = cp.getDistance() + info.m_linearSlop;
    {
      const btVector3 die_vel = die->getVelocityInLocalPoint(rel_pos);
      const btVector3 zero(0, 0, 0);  // the fixed body's velocity
      const btVector3 vel = die_is_a ? die_vel - zero : zero - die_vel;
      const btScalar rel_vel = n.dot(vel);
      r.friction = cp.m_combinedFriction;
      restitution = restitutionCurve(rel_vel, cp.m_combinedRestitution,
                                     info.m_restitutionVelocityThreshold);
      if (restitution <= btScalar(0.)) restitution = 0.f;
    }
    if (info.m_solverMode & SOLVER_USE_WARMSTARTING) {
      r.applied = cp.m_appliedImpulse * info.m_warmstartingFactor;
      // internalApplyImpulse on the die: as body A with the impulse, as body B with both the
      // direction and the impulse negated.
      if (die_is_a) {
        delta_linear_ += r.linear * r.applied * linear_factor_;
        delta_angular_ += r.angular * (r.applied * angular_factor_);
      } else {
        const btScalar minus = -(btScalar)r.applied;
        delta_linear_ += (-r.normal * body.internalGetInvMass()) * minus * linear_factor_;
        delta_angular_ += -r.angular * (minus * angular_factor_);
      }
    } else {
      r.applied = 0.f;
    }
    r.applied_push = 0.f;
    {
      const btScalar dieDotn =
          r.normal.dot(body.m_linearVelocity + body.m_externalForceImpulse) +
          r.torque_axis.dot(body.m_angularVelocity + body.m_externalTorqueImpulse);
      // vel1Dotn + vel2Dotn, the fixed body's being +0.
      const btScalar rel_vel = die_is_a ? dieDotn + btScalar(0) : btScalar(0) + dieDotn;
      btScalar positionalError = 0.f;
      btScalar velocityError = restitution - rel_vel;
      if (penetration > 0) {
        positionalError = 0;
        velocityError -= penetration * invTimeStep;
      } else {
        positionalError = -penetration * erp * invTimeStep;
      }
      const btScalar penetrationImpulse = positionalError * r.jac_diag_inv;
      const btScalar velocityImpulse = velocityError * r.jac_diag_inv;
      if (!info.m_splitImpulse || (penetration > info.m_splitImpulsePenetrationThreshold)) {
        r.rhs = penetrationImpulse + velocityImpulse;
        r.rhs_penetration = 0.f;
      } else {
        r.rhs = velocityImpulse;
        r.rhs_penetration = penetrationImpulse;
      }
      r.cfm = cfm * r.jac_diag_inv;
      r.lower = 0;
      r.upper = 1e10f;
    }
    return contact_rows_ - 1;
  }

  // setupFrictionConstraint (no friction anchor, no slip), the die's side, as contact_row.
  int friction_row(btManifoldPoint& cp, const btVector3& normalAxis, btRigidBody* die,
                   bool die_is_a, const btVector3& rel_pos, btScalar relaxation) {
    Row& r = new_row(frictions_, friction_rows_);
    r.die_is_a = die_is_a;
    r.friction = cp.m_combinedFriction;
    r.applied = 0.f;
    r.applied_push = 0.f;
    r.normal = die_is_a ? normalAxis : -normalAxis;
    r.torque_axis = rel_pos.cross(r.normal);
    r.angular = die->getInvInertiaTensorWorld() * r.torque_axis * die->getAngularFactor();
    const btSolverBody& body = m_tmpSolverBodyPool[kDie];
    r.linear = r.normal * body.internalGetInvMass();
    if (die_is_a) {
      const btScalar denom0 = die->getInvMass() + normalAxis.dot(r.angular.cross(rel_pos));
      r.jac_diag_inv = relaxation / (denom0 + btScalar(0.f));
    } else {
      const btScalar denom1 = die->getInvMass() + normalAxis.dot((-r.angular).cross(rel_pos));
      r.jac_diag_inv = relaxation / (btScalar(0.f) + denom1);
    }
    const btScalar dieDotn = r.normal.dot(body.m_linearVelocity + body.m_externalForceImpulse) +
                             r.torque_axis.dot(body.m_angularVelocity);
    const btScalar rel_vel = die_is_a ? dieDotn + btScalar(0) : btScalar(0) + dieDotn;
    const btScalar velocityError = btScalar(0.) - rel_vel;
    const btScalar velocityImpulse = velocityError * r.jac_diag_inv;
    r.rhs = btScalar(0) + velocityImpulse;
    r.rhs_penetration = 0.f;
    r.cfm = 0.;
    r.lower = -r.friction;
    r.upper = r.friction;
    return friction_rows_ - 1;
  }

  // solveGroupCacheFriendlyIterations: the split-impulse passes, then the velocity passes.
  void iterate(const btContactSolverInfo& info, int numManifolds) {
    const int n = info.m_numIterations;
    if (info.m_splitImpulse) {
      for (int iteration = 0; iteration < n; iteration++) {
        btScalar residual = 0.f;
        for (int i = 0; i < contact_rows_; i++) {
          residual = btMax(residual, square(push(contacts_[i])));
        }
        if (residual <= info.m_leastSquaresResidualThreshold || iteration >= n - 1) break;
      }
    }
    // solveSingleIteration: the contact rows, then the friction rows, each bounded by its
    // contact's impulse so far.
    const int maxIterations = m_maxOverrideNumSolverIterations > n ? m_maxOverrideNumSolverIterations : n;
    for (int iteration = 0; iteration < maxIterations; iteration++) {
      btScalar residual = 0.f;
      if (iteration < n) {
        for (int i = 0; i < contact_rows_; i++) {
          residual = btMax(residual, square(solve<false>(contacts_[i])));
        }
        for (int i = 0; i < friction_rows_; i++) {
          Row& f = frictions_[i];
          const btScalar total = contacts_[f.contact].applied;
          if (total > btScalar(0)) {
            f.lower = -(f.friction * total);
            f.upper = f.friction * total;
            residual = btMax(residual, square(solve<true>(f)));
          }
        }
      }
      m_leastSquaresResidual = residual;
      if (residual <= info.m_leastSquaresResidualThreshold || iteration >= maxIterations - 1) {
        m_analyticsData.m_numSolverCalls++;
        m_analyticsData.m_numIterationsUsed = iteration + 1;
        m_analyticsData.m_islandId = kDie;  // the die's companion id at this point
        m_analyticsData.m_numBodies = 1;
        m_analyticsData.m_numContactManifolds = numManifolds;
        m_analyticsData.m_remainingLeastSquaresResidual = residual;
        break;
      }
    }
  }

  // solveGroupCacheFriendlyFinish: writeBackContacts, then writeBackBodies.
  void finish(btRigidBody* die, const btContactSolverInfo& info) {
    if (info.m_solverMode & SOLVER_USE_WARMSTARTING) {
      for (int i = 0; i < contact_rows_; i++) {
        contacts_[i].point->m_appliedImpulse = contacts_[i].applied;
        contacts_[i].point->m_appliedImpulseLateral1 = frictions_[i].applied;
      }
    }
    btSolverBody& body = m_tmpSolverBodyPool[kDie];
    body.m_deltaLinearVelocity = delta_linear_;
    body.m_deltaAngularVelocity = delta_angular_;
    body.m_pushVelocity = push_;
    body.m_turnVelocity = turn_;
    if (info.m_splitImpulse) {
      body.writebackVelocityAndTransform(info.m_timeStep, info.m_splitImpulseTurnErp);
    } else {
      body.writebackVelocity();
    }
    die->setLinearVelocity(body.m_linearVelocity + body.m_externalForceImpulse);
    die->setAngularVelocity(body.m_angularVelocity + body.m_externalTorqueImpulse);
    if (info.m_splitImpulse) die->setWorldTransform(body.m_worldTransform);
    die->setCompanionId(-1);
  }

  // The floor's side of a row, as Bullet computes it: (0 . 0 + 0 . 0) * J.
  static btScalar fixed_term(const Row& c) { return btScalar(0) * c.jac_diag_inv; }

  // deltaImpulse less both bodies' velocity terms, in Bullet's order (body A's first).
  static btScalar less_velocity(btScalar deltaImpulse, const Row& c, btScalar deltaVelDotn) {
    if (c.die_is_a) {
      deltaImpulse -= deltaVelDotn * c.jac_diag_inv;
      deltaImpulse -= fixed_term(c);
    } else {
      deltaImpulse -= fixed_term(c);
      deltaImpulse -= deltaVelDotn * c.jac_diag_inv;
    }
    return deltaImpulse;
  }

  // gResolveSingleConstraintRowGeneric_scalar_reference (a friction row: both limits) and
  // gResolveSingleConstraintRowLowerLimit_scalar_reference (a contact row: the lower one),
  // which differ only there.
  template <bool kUpperLimit>
  btScalar solve(Row& c) {
    btScalar deltaImpulse = c.rhs - btScalar(c.applied) * c.cfm;
    deltaImpulse = less_velocity(
        deltaImpulse, c, c.normal.dot(delta_linear_) + c.torque_axis.dot(delta_angular_));
    const btScalar sum = btScalar(c.applied) + deltaImpulse;
    if (sum < c.lower) {
      deltaImpulse = c.lower - c.applied;
      c.applied = c.lower;
    } else if (kUpperLimit && sum > c.upper) {
      deltaImpulse = c.upper - c.applied;
      c.applied = c.upper;
    } else {
      c.applied = sum;
    }
    apply(delta_linear_, delta_angular_, c, deltaImpulse);
    return deltaImpulse * (1. / c.jac_diag_inv);
  }

  // btSolverBody::internalApplyImpulse (internalApplyPushImpulse) on the die.
  void apply(btVector3& linear, btVector3& angular, const Row& c, btScalar impulse) const {
    linear += c.linear * impulse * linear_factor_;
    angular += c.angular * (impulse * angular_factor_);
  }

  // gResolveSplitPenetrationImpulse_scalar_reference (less its global statistics counter,
  // gNumSplitImpulseRecoveries).
  btScalar push(Row& c) {
    btScalar deltaImpulse = 0.f;
    if (c.rhs_penetration) {
      deltaImpulse = c.rhs_penetration - btScalar(c.applied_push) * c.cfm;
      deltaImpulse = less_velocity(deltaImpulse, c, c.normal.dot(push_) + c.torque_axis.dot(turn_));
      const btScalar sum = btScalar(c.applied_push) + deltaImpulse;
      if (sum < c.lower) {
        deltaImpulse = c.lower - c.applied_push;
        c.applied_push = c.lower;
      } else {
        c.applied_push = sum;
      }
      apply(push_, turn_, c, deltaImpulse);
    }
    return deltaImpulse * (1. / c.jac_diag_inv);
  }
};
}  // namespace

BulletWorld::BulletWorld(const BulletScene& s)
    : dt_(s.dt),
      mass_(s.mass),
      made_(s.made),
      moments_(s.moments),
      die_friction_(s.die_friction),
      die_restitution_(s.die_restitution),
      planar_(s.planar),
      gyroscopic_(s.gyroscopic_implicit),
      deactivation_(s.deactivation),
      linear_damping_(s.linear_damping),
      angular_damping_(s.angular_damping),
      rolling_friction_(s.rolling_friction),
      contact_stiffness_(s.contact_stiffness),
      contact_damping_(s.contact_damping) {
  config_ = std::make_unique<btDefaultCollisionConfiguration>();
  // A rounded die meets the floor through the convex-convex test (GJK), one point per step:
  // resting on a face it would rock and slide until its manifold held enough. Perturbed
  // tests give it the whole face's points at once, as the box-box test does the sharp die.
  // A die of any shape (a hull, a cylinder) meets the floor the same way, through GJK, and
  // the same perturbed tests give it a face's points at once, on a box floor or a plane.
  const bool shaped = s.solid != SolidKind::Box;
  if (s.made && (s.edge_radius > 0 || shaped)) config_->setConvexConvexMultipointIterations();
  if (shaped) config_->setPlaneConvexMultipointIterations();
  dispatcher_ = std::make_unique<btCollisionDispatcher>(config_.get());
  // Two bodies: the simplest broadphase does (the pair is the same; measured identical).
  broadphase_ = std::make_unique<btSimpleBroadphase>(4);
  if (s.stock_world) {
    if (s.static_ratio != 1) {
      throw std::invalid_argument("Bullet's own solver has one friction: no static ratio");
    }
    solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
  } else {
    auto solver = std::make_unique<DieSolver>();
    solver->static_ratio = s.static_ratio;
    solver->stick_speed = s.stick_speed;
    solver_ = std::move(solver);
  }
  if (s.stock_world) {
    world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), broadphase_.get(),
                                                       solver_.get(), config_.get());
  } else {
    auto world = std::make_unique<DiceWorld>(dispatcher_.get(), broadphase_.get(),
                                             solver_.get(), config_.get());
    world->gyroscopic_scaled = s.gyroscopic_scaled;
    world_ = std::move(world);
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
  if (s.split_every_depth) info.m_splitImpulsePenetrationThreshold = 0;
  info.m_restitutionVelocityThreshold = s.restitution_velocity_threshold;
  info.m_numIterations = s.solver_iterations;
  if (s.two_friction_directions) info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;

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
  // A soft contact: Bullet combines two bodies' stiffnesses as springs in series and sums
  // their dampings, so the floor's are an infinite stiffness and no damping (its defaults
  // would add 0.1 N s/m) and the contact's are the die's own (reset).
  if (contact_stiffness_ > 0) floor_->setContactStiffnessAndDamping(BT_LARGE_FLOAT, 0);
  world_->addRigidBody(floor_.get());

  const btVector3 half(0.5 * s.sides[0], 0.5 * s.sides[1], 0.5 * s.sides[2]);
  if (!made_) {
    die_shape_ = std::make_unique<btBoxShape>(half);
    return;
  }
  // A made die: the body is its principal frame at its centre of mass c, turned by P from the
  // body axes; a point x of the solid in body axes is Pᵀ(x − c) in the body's frame.
  const double r = s.edge_radius;
  const btQuaternion p(s.principal[0], s.principal[1], s.principal[2], s.principal[3]);
  const btVector3 c = vec(s.com);
  if (s.solid == SolidKind::Hull) {
    // A die of any shape: its hull's vertices put straight into the body's frame, Pᵀ(x − c),
    // as the rounded box's balls below. Bullet keeps a convex hull's surface its margin out
    // from the vertices (hull_margin, a hundredth of the die's size at most: Shape::margin).
    auto hull = std::make_unique<btConvexHullShape>();
    for (std::size_t k = 0; k + 2 < s.hull.size(); k += 3) {
      const btVector3 x(s.hull[k], s.hull[k + 1], s.hull[k + 2]);
      hull->addPoint(quatRotate(p.inverse(), x - c), false);
    }
    hull->recalcLocalAabb();
    hull->setMargin(s.hull_margin);
    die_shape_ = std::move(hull);
    return;
  }
  if (r > 0) {
    // The box swept by a ball of radius r is the convex hull of eight balls of radius r at
    // the inner box's corners: exactly btMultiSphereShape's shape, whose balls may sit
    // anywhere, so they are put straight into the body's frame (a compound around it let the
    // die creep as it came to rest). Its margin is r, so that Bullet's shape without margin
    // is the inner box's corners themselves.
    const btVector3 core = half - btVector3(r, r, r);
    btVector3 corners[8];
    btScalar radii[8];
    for (int n = 0; n < 8; ++n) {
      const btVector3 x(n & 1 ? core.x() : -core.x(), n & 2 ? core.y() : -core.y(),
                        n & 4 ? core.z() : -core.z());
      corners[n] = quatRotate(p.inverse(), x - c);
      radii[n] = r;
    }
    auto hull = std::make_unique<btMultiSphereShape>(corners, radii, 8);
    hull->setMargin(r);
    die_shape_ = std::move(hull);
    return;
  }
  if (!s.offset) {
    // Centred and aligned: the body's frame is the box's (the cylinder's) own.
    if (s.solid == SolidKind::Cylinder) {
      die_shape_ = std::make_unique<btCylinderShapeZ>(half);
    } else {
      die_shape_ = std::make_unique<btBoxShape>(half);
    }
    return;
  }
  // The box (a coin: the cylinder along z) as a compound's child, at Pᵀ(−c), turned by Pᵀ.
  if (s.solid == SolidKind::Cylinder) {
    die_solid_ = std::make_unique<btCylinderShapeZ>(half);
  } else {
    die_solid_ = std::make_unique<btBoxShape>(half);
  }
  btTransform solid_at;
  solid_at.setRotation(p.inverse());
  solid_at.setOrigin(quatRotate(p.inverse(), -c));
  auto compound = std::make_unique<btCompoundShape>(false, 1);
  compound->addChildShape(solid_at, die_solid_.get());
  die_shape_ = std::move(compound);
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
  if (made_) {
    inertia = vec(moments_);  // the principal moments, computed exactly in Rust
  } else {
    die_shape_->calculateLocalInertia(mass_, inertia);
  }
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
  // Rolling resistance: Bullet bounds the torque against rolling (and against turning in
  // place) by this times the floor's friction times the contact's push. Its contacts then
  // go through Bullet's own solver, not the shim's (`DieSolver` declines them).
  if (rolling_friction_ > 0) {
    die_->setRollingFriction(rolling_friction_);
    die_->setSpinningFriction(rolling_friction_);
  }
  // A soft contact (model/compliance.rs): each point a spring and a dashpot, which Bullet's
  // solver applies implicitly (ERP = h k/(h k + c), CFM = 1/(h k + c)); its contacts too go
  // through Bullet's own solver (`DieSolver` declines them).
  if (contact_stiffness_ > 0) {
    die_->setContactStiffnessAndDamping(contact_stiffness_, contact_damping_);
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

// One fixed step per call, as DicePhys: stepSimulation(dt, 1, dt). Writes the state after
// it straight into the caller's (Rust's) copy, so that a step and its read cross the FFI
// once and the state is not copied on the way.
void BulletWorld::step(BodyStateFfi& out) {
  if (!die_) throw std::logic_error("step before reset");
  world_->stepSimulation(dt_, 1, dt_);
  read(out);
}

// The same n steps, each with its state read, without returning to Rust: used only to
// measure what crossing the FFI once per step costs.
void BulletWorld::step_n(std::uint32_t n) {
  if (!die_) throw std::logic_error("step before reset");
  volatile double sink = 0;
  BodyStateFfi s{};
  for (std::uint32_t i = 0; i < n; ++i) {
    world_->stepSimulation(dt_, 1, dt_);
    read(s);
    sink = sink + s.position[1] + s.rotation[3] + s.angular_velocity[2];
  }
}

BodyStateFfi BulletWorld::state() const {
  BodyStateFfi out{};
  read(out);
  return out;
}

// The die's state into out (every field; left as it is before the first reset).
void BulletWorld::read(BodyStateFfi& out) const {
  if (!die_) return;
  const btTransform& t = die_->getWorldTransform();
  const btQuaternion q = t.getRotation();
  out.position = arr(t.getOrigin());
  out.rotation = {q.x(), q.y(), q.z(), q.w()};
  out.linear_velocity = arr(die_->getLinearVelocity());
  out.angular_velocity = arr(die_->getAngularVelocity());
  out.sleeping = die_->getActivationState() == ISLAND_SLEEPING;
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
