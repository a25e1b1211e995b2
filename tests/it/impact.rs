//! exploratory
use dicephys::engine::{new_engine, EngineKind};
use dicephys::model::mass::Features;
use dicephys::model::scene::{Mode, Scene};
use dicephys::model::state::BodyState;
use nalgebra::{UnitQuaternion, Vector3};

const SIDE: f64 = 0.016;
const COM_Z: f64 = -0.0045;

fn scene(mu: f64, e: f64, g: f64) -> Scene {
    let mut s = Scene::paper("16x16x16".parse().unwrap(), Mode::ThreeD);
    s.features = Features {
        com: Some([0.0, 0.0, COM_Z]),
        ..Default::default()
    };
    s.friction = mu;
    s.restitution = e;
    s.gravity = g;
    s.validate(false).unwrap();
    s
}

/// Mass and moment about x through the centre of mass.
fn mass_ix(s: &Scene) -> (f64, f64) {
    let m = s.mass();
    let ix = m * (2.0 * SIDE * SIDE / 12.0 - COM_Z * COM_Z);
    (m, ix)
}

#[test]
fn explore() {
    let v0 = 2.0;
    for mu in [0.0, 0.29] {
        for theta_deg in [45.0f64, -45.0] {
            for gap in [-1e-5, 1e-4, 1e-3] {
                let sc = scene(mu, 0.5, 0.0);
                let (m, ix) = mass_ix(&sc);
                let th = theta_deg.to_radians();
                let q = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), th);
                let c = Vector3::new(0.0, 0.0, COM_Z);
                // lowest edge's midpoint relative to COM, world
                let mut best = Vector3::new(0.0, 1e9, 0.0);
                for (y, z) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
                    let p = Vector3::new(0.0, y * SIDE / 2.0, z * SIDE / 2.0);
                    let r = q * (p - c);
                    if r.y < best.y {
                        best = r;
                    }
                }
                let r = best;
                let e = 0.5;
                let kn = 1.0 / m + r.z * r.z / ix;
                let j = (1.0 + e) * v0 / kn;
                let vy = -v0 + j / m;
                let wx = -r.z * j / ix;
                // rough: sticking
                let knt = -r.y * r.z / ix;
                let ktt = 1.0 / m + r.y * r.y / ix;
                let det = kn * ktt - knt * knt;
                let (mut py, mut pz) = (ktt * (1.0 + e) * v0 / det, -knt * (1.0 + e) * v0 / det);
                if pz.abs() > mu * py {
                    let sg = pz.signum();
                    py = (1.0 + e) * v0 / (kn + sg * mu * knt);
                    pz = sg * mu * py;
                }
                let (rvy, rvz, rwx) = (-v0 + py / m, pz / m, (r.y * pz - r.z * py) / ix);
                for kind in [EngineKind::Bullet, EngineKind::Rapier] {
                    let mut eng = new_engine(kind, &sc).unwrap();
                    let start = BodyState {
                        position: Vector3::new(0.0, -r.y + gap, 0.0),
                        rotation: q,
                        linear_velocity: Vector3::new(0.0, -v0, 0.0),
                        angular_velocity: Vector3::zeros(),
                        sleeping: false,
                    };
                    eng.reset(&start).unwrap();
                    for k in 0..40 {
                        eng.step().unwrap();
                        let s = eng.state();
                        if std::env::var("TRACE").is_ok() && mu == 0.0 && theta_deg > 0.0 && k < 12
                        {
                            println!("  {kind:?} gap {gap:e} step {k}: y {:.6} v=({:.5},{:.5},{:.5}) w=({:.4},{:.4},{:.4})", s.position.y*1e3,
                              s.linear_velocity.x, s.linear_velocity.y, s.linear_velocity.z,
                              s.angular_velocity.x, s.angular_velocity.y, s.angular_velocity.z);
                        }
                    }
                    let a = eng.state();
                    for _ in 0..10 {
                        eng.step().unwrap();
                    }
                    let b = eng.state();
                    let free = (a.angular_velocity - b.angular_velocity).norm() < 1e-9
                        && (a.linear_velocity - b.linear_velocity).norm() < 1e-9;
                    println!(
                        "mu {mu} th {theta_deg} gap {gap:e} {kind:?}: r=({:.3},{:.3})mm free {free} v=({:.5},{:.5},{:.5}) w=({:.4},{:.4},{:.4}) | frictionless vy {vy:.5} wx {wx:.4} | LCP vy {rvy:.5} vz {rvz:.5} wx {rwx:.4}",
                        r.y * 1e3, r.z * 1e3,
                        b.linear_velocity.x, b.linear_velocity.y, b.linear_velocity.z,
                        b.angular_velocity.x, b.angular_velocity.y, b.angular_velocity.z
                    );
                }
            }
        }
    }
}
