// The C++ side of dicephys: only what a die on a floor needs from Bullet. A world with a
// static floor and one box body; reset the box to a throw, step, read its state. Every
// setting comes from Rust (BulletScene); all logic (throws, settling, outcomes) lives there.
#pragma once
#include <array>
#include <memory>

#include "rust/cxx.h"

class btDefaultCollisionConfiguration;
class btCollisionDispatcher;
class btBroadphaseInterface;
class btSequentialImpulseConstraintSolver;
class btDiscreteDynamicsWorld;
class btCollisionShape;
class btRigidBody;

namespace dicephys {

struct BulletScene;
struct BodyStateFfi;

class BulletWorld {
 public:
  explicit BulletWorld(const BulletScene& scene);
  ~BulletWorld();
  BulletWorld(const BulletWorld&) = delete;
  BulletWorld& operator=(const BulletWorld&) = delete;

  void reset(const BodyStateFfi& start);
  void set_state(const BodyStateFfi& now);
  void step(BodyStateFfi& out);
  void step_n(std::uint32_t n);
  BodyStateFfi state() const;
  void read(BodyStateFfi& out) const;
  std::uint32_t contact_points() const;

 private:
  // Declaration order is destruction order, reversed: the world goes first.
  std::unique_ptr<btDefaultCollisionConfiguration> config_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;
  std::unique_ptr<btCollisionShape> floor_shape_;
  std::unique_ptr<btRigidBody> floor_;
  // A made die's own shape (box or rounded box), held by die_shape_, a compound that puts
  // it off the body's frame (the principal frame at the centre of mass); unused for the
  // paper's block, whose shape is die_shape_ itself.
  std::unique_ptr<btCollisionShape> die_solid_;
  std::unique_ptr<btCollisionShape> die_shape_;
  std::unique_ptr<btRigidBody> die_;
  double dt_;
  double mass_;
  bool made_;
  std::array<double, 3> moments_;
  double die_friction_;
  double die_restitution_;
  bool planar_;
  bool gyroscopic_;
  bool deactivation_;
  double linear_damping_;
  double angular_damping_;
  double rolling_friction_;
  double contact_stiffness_;
  double contact_damping_;
};

std::unique_ptr<BulletWorld> new_world(const BulletScene& scene);
std::int32_t bullet_version();

}  // namespace dicephys
