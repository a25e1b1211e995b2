//! What Rapier's 3D and 2D engines share, word for word: the combine rules, the world, the
//! floor, the die's broad-phase leaf (`Flight::aabb`, `refatten`, `leaf_clear`), the step with
//! its bookkeeping for the own flight, and the checks' view of the world. The two crates'
//! types (`Vector`, `Pose`, `Aabb`, ...) differ, so this is a macro, expanded in `rapier3d` and
//! `rapier2d` with each crate's prelude in scope: each gets its own copy, compiled as if
//! written there.

/// Expands the shared items in an engine module: `$name` is its name in error messages.
macro_rules! shared {
    ($name:literal) => {
        /// A collider whose friction and restitution combine as in Bullet: the product of the
        /// two colliders' (Rapier's default is their average). Both colliders say Multiply, so
        /// no rule outranks it.
        fn multiply(c: ColliderBuilder) -> ColliderBuilder {
            c.friction_combine_rule(CoefficientCombineRule::Multiply)
                .restitution_combine_rule(CoefficientCombineRule::Multiply)
        }

        /// A world with the scene's gravity (along −y) and step, and no CCD, as DicePhys (0
        /// also turns off Rapier's automatic CCD of fast bodies), with the floor in it: `boxed`,
        /// DicePhys's static box (its top face at y = 0) given its half extents, or the plane.
        fn world_with_floor(
            scene: &Scene,
            gravity: Vector,
            boxed: ColliderBuilder,
        ) -> PhysicsWorld {
            let mut world = PhysicsWorld::new();
            world.gravity = gravity;
            world.integration_parameters.dt = scene.dt;
            world.integration_parameters.max_ccd_substeps = 0;
            let floor = match scene.floor {
                Floor::Box => boxed,
                Floor::Plane => ColliderBuilder::new(SharedShape::halfspace(Vector::Y)),
            };
            world.insert_collider(
                multiply(
                    floor
                        .friction(scene.floor_friction)
                        .restitution(scene.floor_restitution),
                ),
                None,
            );
            world
        }

        impl Flight {
            /// The broad-phase AABB of the die at body pose `p`, as `compute_broad_phase_aabb`.
            fn aabb(&self, world: &PhysicsWorld, p: &Pose) -> Aabb {
                let co = &world.colliders[self.collider];
                co.shape()
                    .compute_aabb(&(*p * self.co_offset))
                    .loosened(self.loosen)
            }

            /// The leaf after Rapier's `set_aabb` of `aabb` on leaf `leaf`, if it changed.
            fn refatten(&self, leaf: &Aabb, aabb: &Aabb) -> Option<Aabb> {
                let contains = leaf.mins.cmple(aabb.mins).all() && leaf.maxs.cmpge(aabb.maxs).all();
                (!contains).then(|| Aabb {
                    mins: aabb.mins - Vector::splat(self.skin),
                    maxs: aabb.maxs + Vector::splat(self.skin),
                })
            }

            /// The leaf lies above the floor's (fattened): no new pair can form.
            fn leaf_clear(&self, leaf: &Aabb) -> bool {
                leaf.mins.y > self.floor_top
            }
        }

        /// The floor leaf's top with the change-detection skin on top of it, to spare: every
        /// collider's but the die's.
        fn floor_top(w: &PhysicsWorld, die: ColliderHandle, skin: f64) -> f64 {
            let p = &w.integration_parameters;
            w.colliders
                .iter()
                .filter(|(ch, _)| *ch != die)
                .map(|(_, c)| c.compute_broad_phase_aabb(p, &w.bodies).maxs.y)
                .fold(f64::NEG_INFINITY, f64::max)
                + skin
        }

        /// What the world keeps of the die besides its state, for checks: its contact pairs
        /// (with any manifold, empty or not), its sleep timer, and whether it sleeps.
        fn die_world_of(
            world: &PhysicsWorld,
            die: Option<RigidBodyHandle>,
        ) -> Option<(usize, f64, bool)> {
            let b = &world.bodies[die?];
            let pairs = world
                .narrow_phase
                .contact_pairs_with(b.colliders()[0])
                .count();
            Some((pairs, b.activation().time_since_can_sleep, b.is_sleeping()))
        }

        /// One engine step: the pose before it kept for the sleep rule (unless asleep), the
        /// flight under way dropped, the leaf refattened as Rapier's tree does. Rapier does not
        /// let a NaN through: it puts the body back at its last finite pose with zero velocity
        /// and disables it, which would look like a die at rest; it is reported instead.
        fn step_world(
            world: &mut PhysicsWorld,
            die: Option<RigidBodyHandle>,
            flight: &mut Option<Flight>,
        ) -> crate::Result<()> {
            let Some(h) = die else {
                return Err(crate::Error::Engine(
                    concat!($name, ": step before reset").into(),
                ));
            };
            if let Some(f) = flight.as_mut() {
                let b = &world.bodies[h];
                f.sleep_prev = (!b.is_sleeping()).then(|| *b.position());
                f.course = None;
            }
            world.step();
            if let Some(f) = flight.as_mut() {
                let aabb = f.aabb(world, world.bodies[h].position());
                if let Some(l) = f.refatten(&f.leaf, &aabb) {
                    f.leaf = l;
                }
            }
            if !world.quarantine().is_empty() {
                return Err(crate::Error::Engine(
                    concat!($name, ": the die's state went non-finite (quarantined)").into(),
                ));
            }
            Ok(())
        }
    };
}

pub(super) use shared;
