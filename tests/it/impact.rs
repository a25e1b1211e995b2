//! exploratory
use dicephys::engine::{new_engine, EngineKind};
use dicephys::model::mass::Features;
use dicephys::model::scene::{Mode, Scene};
use dicephys::model::state::BodyState;
use nalgebra::{UnitQuaternion, Vector3};

const SIDE: f64 = 0.016;

fn scene(com_z: f64, mu: f64, e: f64, g: f64, dt: f64) -> Scene {
    let mut s = Scene::paper("16x16x16".parse().unwrap(), Mode::ThreeD);
    if com_z != 0.0 {
        s.features = Features {
            com: Some([0.0, 0.0, com_z]),
            ..Default::default()
        };
    }
    s.friction = mu;
    s.restitution = e;
    s.gravity = g;
    s.dt = dt;
    s.validate(false).unwrap();
    s
}

#[test]
fn explore() {
    let v0 = 2.0;
    let e = 0.5;
    let gap = -1e-7;
    for dt in [1e-3, 2.5e-4] {
        for (com_z, theta_deg) in [
            (-0.0045, 45.0f64),
            (-0.0045, -45.0),
            (0.0, 45.0),
            (0.0, 30.0),
            (0.0, 15.0),
            (-0.0045, 30.0),
        ] {
            let sc = scene(com_z, 0.0, e, 0.0, dt);
            let m = sc.mass();
            let ix = m * (2.0 * SIDE * SIDE / 12.0 - com_z * com_z);
            let th = theta_deg.to_radians();
            let q = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), th);
            let c = Vector3::new(0.0, 0.0, com_z);
            let mut r = Vector3::new(0.0, 1e9, 0.0);
            for (y, z) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
                let p = q * (Vector3::new(0.0, y * SIDE / 2.0, z * SIDE / 2.0) - c);
                if p.y < r.y {
                    r = p;
                }
            }
            let kn = 1.0 / m + r.z * r.z / ix;
            let j = (1.0 + e) * v0 / kn;
            let dv = j / m;
            let wx = -r.z * j / ix;
            for kind in [EngineKind::Bullet, EngineKind::Rapier] {
                let mut eng = new_engine(kind, &sc).unwrap();
                eng.reset(&BodyState {
                    position: Vector3::new(0.0, -r.y + gap, 0.0),
                    rotation: q,
                    linear_velocity: Vector3::new(0.0, -v0, 0.0),
                    angular_velocity: Vector3::zeros(),
                    sleeping: false,
                })
                .unwrap();
                let mut out = String::new();
                for k in 0..3 {
                    eng.step().unwrap();
                    let s = eng.state();
                    let edv = (s.linear_velocity.y + v0) / dv - 1.0;
                    let ewx = if wx != 0.0 {
                        s.angular_velocity.x / wx - 1.0
                    } else {
                        s.angular_velocity.x
                    };
                    out += &format!(
                        " | s{k}: dv {edv:+.4} wx {ewx:+.4} wy {:+.2} wz {:+.2} vz {:+.4}",
                        s.angular_velocity.y, s.angular_velocity.z, s.linear_velocity.z
                    );
                }
                println!("dt {dt} com {com_z} th {theta_deg} r=({:.2},{:.2}) dv {dv:.4} wx {wx:.2} {kind:?}{out}", r.y*1e3, r.z*1e3);
            }
        }
    }
}

#[test]
fn explore_rapier_iterations() {
    use rapier3d_f64::prelude::*;
    let com_z = -0.0045;
    let (v0, e) = (2.0, 0.5);
    let m = 800.0 * SIDE * SIDE * SIDE;
    let ix = m * (2.0 * SIDE * SIDE / 12.0 - com_z * com_z);
    let iz = m * (2.0 * SIDE * SIDE / 12.0);
    let th = 45f64.to_radians();
    let q = nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Vector3::x_axis(), th);
    let c = nalgebra::Vector3::new(0.0, 0.0, com_z);
    let r = q * (nalgebra::Vector3::new(0.0, -SIDE / 2.0, SIDE / 2.0) - c);
    let kn = 1.0 / m + r.z * r.z / ix;
    let j = (1.0 + e) * v0 / kn;
    for (iters, pgs) in [(1, 1), (2, 1), (4, 1), (8, 1), (16, 1), (4, 4), (4, 16)] {
        let mut w = PhysicsWorld::new();
        w.gravity = Vector::new(0.0, 0.0, 0.0);
        w.integration_parameters.dt = 1e-3;
        w.integration_parameters.max_ccd_substeps = 0;
        w.integration_parameters.num_solver_iterations = iters;
        w.integration_parameters.num_internal_pgs_iterations = pgs;
        w.insert_collider(
            ColliderBuilder::cuboid(5000.0, 50.0, 5000.0)
                .translation(Vector::new(0.0, -50.0, 0.0))
                .friction(1.0)
                .restitution(1.0)
                .friction_combine_rule(CoefficientCombineRule::Multiply)
                .restitution_combine_rule(CoefficientCombineRule::Multiply),
            None,
        );
        let qq = q.quaternion();
        let body = RigidBodyBuilder::dynamic()
            .pose(Pose::from_parts(
                Vector::new(0.0, -r.y - 1e-7, 0.0),
                Rotation::from_xyzw(qq.i, qq.j, qq.k, qq.w),
            ))
            .linvel(Vector::new(0.0, -v0, 0.0))
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                m,
                Vector::new(ix, ix, iz),
            ));
        let col = ColliderBuilder::cuboid(SIDE / 2.0, SIDE / 2.0, SIDE / 2.0)
            .position(Pose::from_parts(
                Vector::new(0.0, 0.0, -com_z),
                Rotation::IDENTITY,
            ))
            .density(0.0)
            .friction(0.0)
            .restitution(e)
            .friction_combine_rule(CoefficientCombineRule::Multiply)
            .restitution_combine_rule(CoefficientCombineRule::Multiply);
        let (h, _) = w.insert(body, col);
        w.step();
        let b = &w.bodies[h];
        let dv = (b.linvel().y + v0) / (j / m) - 1.0;
        let wx = b.angvel().x / (-r.z * j / ix) - 1.0;
        println!(
            "iters {iters} pgs {pgs}: dv {dv:+.5} wx {wx:+.5} wz {:+.3}",
            b.angvel().z
        );
    }
}
