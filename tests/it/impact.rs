//! A loaded die's impacts against closed forms (issue 46, class N: the engines disagree about a
//! loaded cube that bounces). Each engine is driven through the library's own `Engine` (reset
//! to a start state, step, read the state), on scenes whose answer is known exactly:
//!
//! - free flight with gravity off: the centre of mass stays put;
//! - the cube balanced on an edge: it falls to the side its centre of mass lies on;
//! - the cube falling without rotation onto one edge (tilted about x, so the problem is 2D in
//!   the y–z plane), frictionless, restitution e: the single-contact impulse law gives
//!   J = (1 + e) V / (1/m + r_z²/I_x), v' = −V + J/m, ω'_x = −r_z J / I_x, with r the edge
//!   from the centre of mass and I_x the moment about the x axis through it;
//! - the same edge landing while sliding across it, with friction: Newton's restitution and
//!   Coulomb's friction on the whole impulse (J_z = −μ J_y, J_y = (1 + e) V/(K_yy − μ K_yz));
//! - the centred cube sliding and spinning flat on a face: Coulomb's law at its corners.
//!
//! The cube: 16 mm, density 800, centre of mass 4.5 mm toward its −z face, so I_x =
//! m (2·16²/12 − 4.5²) mm² = 22.42 m mm² (42.67 m mm² about the centre) and I_z = 42.67 m mm².

use dicephys::engine::{new_engine, Engine, EngineKind};
use dicephys::model::mass::{Features, MassProps};
use dicephys::model::scene::{Mode, Preset, Scene};
use dicephys::model::state::{up_in_body, BodyState};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

const SIDE: f64 = 0.016;
const COM_Z: f64 = -0.0045;
/// Approach speed, m/s (a die dropped 0.2 m lands at 2 m/s).
const V: f64 = 2.0;
const E: f64 = 0.5;
/// Bullet's Baumgarte factor for contacts (`btContactSolverInfo::m_erp2`, 3.24's default).
const BULLET_ERP: f64 = 0.2;

/// The 16 mm cube with its centre of mass at (0, 0, `com_z`), as `roll --com` makes it.
fn cube(com_z: f64, friction: f64, gravity: f64, dt: f64) -> Scene {
    let mut s = Scene::paper("16x16x16".parse().unwrap(), Mode::ThreeD);
    if com_z != 0.0 {
        s.features = Features {
            com: Some([0.0, 0.0, com_z]),
            ..Default::default()
        };
    }
    s.friction = friction;
    s.restitution = E;
    s.gravity = gravity;
    s.dt = dt;
    s.validate(false).unwrap();
    s
}

fn at_rest(position: Vector3<f64>, rotation: UnitQuaternion<f64>) -> BodyState {
    BodyState {
        position,
        rotation,
        linear_velocity: Vector3::zeros(),
        angular_velocity: Vector3::zeros(),
        sleeping: false,
    }
}

/// An edge impact: the cube turned by `theta` about x falls straight down at V onto the edge
/// parallel to x that is lowest.
struct EdgeImpact {
    m: f64,
    ix: f64,
    rotation: UnitQuaternion<f64>,
    /// The edge's midpoint from the centre of mass, world axes.
    r: Vector3<f64>,
}

impl EdgeImpact {
    fn new(scene: &Scene, com_z: f64, theta_deg: f64) -> EdgeImpact {
        let m = scene.mass();
        let ix = m * (2.0 * SIDE * SIDE / 12.0 - com_z * com_z);
        let rotation = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), theta_deg.to_radians());
        let c = Vector3::new(0.0, 0.0, com_z);
        let r = [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)]
            .map(|(y, z)| rotation * (Vector3::new(0.0, y, z) * (SIDE / 2.0) - c))
            .into_iter()
            .min_by(|a, b| a.y.total_cmp(&b.y))
            .unwrap();
        EdgeImpact { m, ix, rotation, r }
    }

    /// The impulse law: (J/m, the velocity change; ω'_x).
    fn law(&self) -> (f64, f64) {
        let j = (1.0 + E) * V / (1.0 / self.m + self.r.z * self.r.z / self.ix);
        (j / self.m, -self.r.z * j / self.ix)
    }

    /// The state one step after the die, its edge `gap` above the floor (negative: into it),
    /// starts falling, gravity off.
    fn after(&self, engine: &mut dyn Engine, gap: f64) -> BodyState {
        self.after_steps(engine, gap, 1)
    }

    /// The same after `steps` steps.
    fn after_steps(&self, engine: &mut dyn Engine, gap: f64, steps: usize) -> BodyState {
        engine
            .reset(&BodyState {
                linear_velocity: Vector3::new(0.0, -V, 0.0),
                ..at_rest(Vector3::new(0.0, -self.r.y + gap, 0.0), self.rotation)
            })
            .unwrap();
        for _ in 0..steps {
            engine.step().unwrap();
        }
        engine.state()
    }
}

/// Asserts a step's (Δv, ω'_x) within `tol` (relative) of the impulse law's, naming `what`.
fn assert_meets_law(what: &str, got: (f64, f64), law: (f64, f64), tol: f64) {
    assert!(
        rel(got.0, law.0).abs() < tol,
        "{what}: Δv {} against {}",
        got.0,
        law.0
    );
    assert!(
        rel(got.1, law.1).abs() < tol,
        "{what}: ω'_x {} against {}",
        got.1,
        law.1
    );
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b) / b
}

/// Gravity off, spinning about no principal axis: the centre of mass stays within 1e-12 m of
/// where it started for 200 steps on every engine (an engine that turned the body about its
/// geometric centre, or about the wrong offset, would carry it around a 4.5 mm circle).
#[test]
fn in_free_flight_the_loaded_cube_turns_about_its_centre_of_mass() {
    let scene = cube(COM_Z, 0.29, 0.0, 0.001);
    let start = BodyState {
        angular_velocity: Vector3::new(30.0, -50.0, 80.0),
        ..at_rest(
            Vector3::new(0.0, 0.5, 0.0),
            UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1),
        )
    };
    for kind in [EngineKind::Bullet, EngineKind::Rapier, EngineKind::Moreau] {
        let mut engine = new_engine(kind, &scene).unwrap();
        engine.reset(&start).unwrap();
        for _ in 0..200 {
            engine.step().unwrap();
        }
        let moved = (engine.state().position - start.position).norm();
        assert!(
            moved < 1e-12,
            "{kind:?}: the centre of mass moved {moved:e} m"
        );
    }
}

/// Balanced on the edge between its −y and −z faces, the loaded cube's centre of mass is above
/// the edge at a tilt of atan(3.5/8) = 23.63° (45° if it were centred, 57.4° with the offset's
/// sign flipped). Released at rest 2° either side, on every engine, it falls the way its centre
/// of mass lies: back onto −y, or over onto −z (its up direction, after 2 s, within 0.05 rad of
/// that face's opposite).
#[test]
fn balanced_on_an_edge_the_loaded_cube_falls_the_way_its_centre_of_mass_lies() {
    let scene = cube(COM_Z, 0.29, scene_gravity(), 0.001);
    let critical = (3.5f64 / 8.0).atan().to_degrees();
    for kind in [EngineKind::Bullet, EngineKind::Rapier, EngineKind::Moreau] {
        let mut engine = new_engine(kind, &scene).unwrap();
        for (tilt, up) in [
            (critical - 2.0, Vector3::y()),
            (critical + 2.0, Vector3::z()),
        ] {
            let rotation = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -tilt.to_radians());
            // The edge (y, z) = (−8, −8) mm, from the centre of mass, is the lowest point.
            let edge = rotation
                * (Vector3::new(0.0, -SIDE / 2.0, -SIDE / 2.0) - Vector3::new(0.0, 0.0, COM_Z));
            engine
                .reset(&at_rest(Vector3::new(0.0, -edge.y, 0.0), rotation))
                .unwrap();
            for _ in 0..2000 {
                engine.step().unwrap();
            }
            let got = up_in_body(&engine.state().rotation);
            assert!(
                got.angle(&up) < 0.05,
                "{kind:?} at {tilt:.2}°: up {got:?}, should be {up:?}"
            );
        }
    }
}

fn scene_gravity() -> f64 {
    Scene::paper("16x16x16".parse().unwrap(), Mode::ThreeD).gravity
}

/// The off-centre lever on both engines: whatever an engine's impulse, it turns the cube by
/// ω'_x = −(m r_z / I_x) Δv_y. That ratio is the mass, the moment about the centre of mass and
/// the offset's sign and size together (the moment about the geometric centre would be 90 %
/// off, the offset's sign flipped 180 % at 45°). Frictionless, so v_z stays 0 (within 1e-9
/// m/s). Within 1e-3, at tilts ±45° (the weight away from, and toward, the edge that lands)
/// and ±30°.
#[test]
fn an_edge_impact_turns_the_loaded_cube_by_its_lever_on_both_engines() {
    let scene = cube(COM_Z, 0.0, 0.0, 0.001);
    for kind in [EngineKind::Bullet, EngineKind::Rapier] {
        let mut engine = new_engine(kind, &scene).unwrap();
        for theta in [45.0, -45.0, 30.0, -30.0] {
            let hit = EdgeImpact::new(&scene, COM_Z, theta);
            let s = hit.after(engine.as_mut(), -1e-9);
            let dv = s.linear_velocity.y + V;
            let lever = -hit.m * hit.r.z / hit.ix;
            let got = s.angular_velocity.x / dv;
            println!(
                "{kind:?} {theta}°: r = ({:.3}, {:.3}) mm, ω'_x/Δv_y {got:.3} against {lever:.3} \
                 ({:+.1e})",
                hit.r.y * 1e3,
                hit.r.z * 1e3,
                rel(got, lever)
            );
            assert!(
                rel(got, lever).abs() < 1e-3,
                "{kind:?} {theta}°: ω'_x/Δv_y {got} against −m r_z/I_x {lever}"
            );
            assert!(
                s.linear_velocity.z.abs() < 1e-9,
                "{kind:?} {theta}°: v_z {}",
                s.linear_velocity.z
            );
        }
    }
}

/// Bullet meets the impulse law itself: touching the floor as the step starts (1e-9 m in, so
/// its box-box test finds the edge), v' and ω'_x within 1e-5 of the law, for the loaded cube
/// and for a centred cube tilted 30° (whose edge is off the centre too). Found deeper, d into
/// the floor, Bullet bounces harder by exactly its Baumgarte term: it folds the position error
/// into the velocity solve (`cpp/shim.cc`, `contact_row`: split impulse only beyond 4 cm,
/// `m_splitImpulsePenetrationThreshold`), so the edge leaves at e V + 0.2 d/dt; a die landing
/// at V is found up to V·dt deep, so its restitution is e + 0.2 U, U uniform in [0, 1):
/// 0.6 on average for e = 0.5. Within 1e-4 of that, from 0.1 mm and 1 mm above the floor.
#[test]
fn bullet_meets_the_impulse_law_and_adds_its_baumgarte_term() {
    for (com_z, theta) in [(COM_Z, 45.0), (COM_Z, -45.0), (COM_Z, 30.0), (0.0, 30.0)] {
        let scene = cube(com_z, 0.0, 0.0, 0.001);
        let mut engine = new_engine(EngineKind::Bullet, &scene).unwrap();
        let hit = EdgeImpact::new(&scene, com_z, theta);
        let (dv, wx) = hit.law();
        let s = hit.after(engine.as_mut(), -1e-9);
        let (got_dv, got_wx) = (s.linear_velocity.y + V, s.angular_velocity.x);
        println!(
            "Bullet com {com_z} {theta}°: Δv {got_dv:.5} ({:+.1e}), ω'_x {got_wx:.3} ({:+.1e}) \
             against {dv:.5}, {wx:.3}",
            rel(got_dv, dv),
            rel(got_wx, wx)
        );
        assert_meets_law(
            &format!("Bullet {theta}°"),
            (got_dv, got_wx),
            (dv, wx),
            1e-5,
        );
        for gap in [1e-4, 1e-3] {
            // Found after one step, V dt − gap deep: the edge leaves at e V + 0.2 d/dt.
            let d = V * scene.dt - gap;
            let boost = (E * V + BULLET_ERP * d / scene.dt + V) / ((1.0 + E) * V);
            let got = hit.after_steps(engine.as_mut(), gap, 2).linear_velocity.y + V;
            println!(
                "Bullet com {com_z} {theta}° from {gap:e} m: Δv {got:.5} = law × {:.5}, \
                 Baumgarte predicts × {boost:.5}",
                got / dv
            );
            assert!(
                rel(got / dv, boost).abs() < 1e-4,
                "Bullet {theta}° from {gap} m: Δv {got} = law × {}, not × {boost}",
                got / dv
            );
        }
    }
}

/// The fix for Bullet's term: `--preset split` pushes a contact found deep out with a split
/// impulse, apart from its velocity, so the edge found 0.1 mm and 1 mm into the floor leaves
/// at the impulse law itself (within 1e-4), where dicephys281 bounces it up to 20 % harder
/// (the test above). Touching, the two presets are the same.
#[test]
fn with_the_split_preset_bullet_meets_the_impulse_law_from_any_depth() {
    for (com_z, theta) in [(COM_Z, 45.0), (COM_Z, -45.0), (COM_Z, 30.0), (0.0, 30.0)] {
        let mut scene = cube(com_z, 0.0, 0.0, 0.001);
        scene.preset = Preset::Split;
        let mut engine = new_engine(EngineKind::Bullet, &scene).unwrap();
        let hit = EdgeImpact::new(&scene, com_z, theta);
        let (dv, wx) = hit.law();
        for gap in [-1e-9, 1e-4, 1e-3] {
            // From above the floor the impact is the second step's.
            let s = hit.after_steps(engine.as_mut(), gap, if gap > 0.0 { 2 } else { 1 });
            let (got_dv, got_wx) = (s.linear_velocity.y + V, s.angular_velocity.x);
            println!(
                "Bullet split com {com_z} {theta}° from {gap:e} m: Δv = law × {:.5}, ω'_x = law \
                 × {:.5}",
                got_dv / dv,
                got_wx / wx
            );
            let what = format!("{theta}° from {gap} m");
            assert_meets_law(&what, (got_dv, got_wx), (dv, wx), 1e-4);
        }
    }
}

/// Rapier's edge impact, predicted: its substeps bring the edge's two contact points (x = ±8 mm)
/// to rest together, converged (the inelastic impulse V/(1/m + r_z²/I_x)); then its end-of-step
/// restitution pass (rapier3d-f64 0.36.1, `staged_island_solver/worker.rs`, "applied ONCE
/// after all substeps") drives each point's normal velocity to e V once, one point after the
/// other: the first gets e V/K₁₁, the second (e V − K₂₁ Δ₁)/K₂₂, where K is the two points'
/// coupling (K₁₁ = 1/m + r_z²/I_x + a² (I⁻¹)_zz, K₁₂ = 1/m + r_z²/I_x − a² (I⁻¹)_zz, a = 8 mm).
/// The impulse falls short of the law (4.0 % at ±45°, 2.1 % for a centred cube at 30°) or
/// overshoots it (3.3 % at 30°, where the two points' coupling K₁₂ is positive), and the
/// difference of the two tips the die about the horizontal axis across the edge, world z
/// (15 rad/s at ±45°, also for a centred cube). Measured: the model accounts for at least 90 % of the departure (all of it at
/// ±45°, to 1e-4), and for the spin within 10 %, whatever the step (1 ms, 0.25 ms).
#[test]
fn rapier_bounces_an_edge_with_one_sequential_restitution_pass() {
    for dt in [0.001, 0.00025] {
        for (com_z, theta) in [
            (COM_Z, 45.0),
            (COM_Z, -45.0),
            (COM_Z, 30.0),
            (0.0, 45.0),
            (0.0, 30.0),
        ] {
            let scene = cube(com_z, 0.0, 0.0, dt);
            let mut engine = new_engine(EngineKind::Rapier, &scene).unwrap();
            let hit = EdgeImpact::new(&scene, com_z, theta);
            let (m, a) = (hit.m, SIDE / 2.0);
            // (I⁻¹)_zz in world axes: body z turned by θ about x mixes I_y = I_x and I_z.
            let iz = m * 2.0 * SIDE * SIDE / 12.0;
            let th = theta.to_radians();
            let inv_zz = th.sin().powi(2) / hit.ix + th.cos().powi(2) / iz;
            let common = 1.0 / m + hit.r.z * hit.r.z / hit.ix;
            let (k11, k12) = (common + a * a * inv_zz, common - a * a * inv_zz);
            let inelastic = V / common;
            let d1 = E * V / k11;
            let d2 = (E * V - k12 * d1) / k11;
            let predicted = (inelastic + d1 + d2) / m;
            let spin = inv_zz * a * (d2 - d1);
            let (dv, _) = hit.law();
            let s = hit.after(engine.as_mut(), -1e-9);
            let got = s.linear_velocity.y + V;
            println!(
                "Rapier dt {dt} com {com_z} {theta}°: Δv {got:.5} = law {:+.2} %, one-pass model \
                 {:+.2} %; tip |ω_z| {:.2} rad/s, model {:.2}",
                100.0 * rel(got, dv),
                100.0 * rel(predicted, dv),
                tip_across_the_edge(&s),
                spin.abs()
            );
            // The model, not the law: at least 90 % of Rapier's departure from the law is the
            // one pass's.
            assert!(
                (got - predicted).abs() < 0.1 * (dv - predicted).abs(),
                "Rapier dt {dt} {theta}°: Δv {got}, one-pass model {predicted}, law {dv}"
            );
            assert!(
                (tip_across_the_edge(&s) - spin.abs()).abs() < 0.1 * spin.abs(),
                "Rapier {theta}°: spin {} against {}",
                tip_across_the_edge(&s),
                spin.abs()
            );
        }
    }
}

/// The tip about world z (across the edge) that unequal impulses at the edge's two ends leave.
fn tip_across_the_edge(s: &BodyState) -> f64 {
    s.angular_velocity.z.abs()
}

/// The exact limit on Rapier: v' and ω'_x within 0.5 % of the impulse law, as Bullet meets it
/// within 1e-5. Rapier meets it under `laws`, whose restitution pass (patched:
/// vendor/rapier3d-f64/PATCH.md) is swept until the edge's two points agree; under the other
/// presets (Rapier's own pass, once) it fails by −4.0 % and a 15 rad/s tip across the edge at
/// ±45°, pinned in `rapier_bounces_an_edge_with_one_sequential_restitution_pass`.
#[test]
fn rapier_under_laws_meets_the_impulse_law() {
    let mut scene = cube(COM_Z, 0.0, 0.0, 0.001);
    scene.preset = Preset::Laws;
    let mut engine = new_engine(EngineKind::Rapier, &scene).unwrap();
    for theta in [45.0, -45.0, 30.0] {
        let hit = EdgeImpact::new(&scene, COM_Z, theta);
        let (dv, wx) = hit.law();
        let s = hit.after(engine.as_mut(), -1e-9);
        let (got_dv, got_wx) = (s.linear_velocity.y + V, s.angular_velocity.x);
        assert_meets_law(
            &format!("Rapier {theta}°"),
            (got_dv, got_wx),
            (dv, wx),
            5e-3,
        );
    }
}

/// `crosscheck`, `roll` and `fair` of a loaded die under the paper's preset, or split, say on
/// stderr that it is rolled off the closed forms and name `--preset laws`; under laws (which
/// `crosscheck` runs unless told otherwise), on the arbiter alone, for a die not loaded, or for
/// one whose pips move its centre of mass by a few hundredths of a millimetre, they say nothing.
#[test]
fn a_loaded_die_off_the_laws_preset_names_it() {
    let note = |command: &str, extra: &[&str]| {
        let mut args = vec![command, "--block", "16x16x16", "--throw", "tumble"];
        args.extend_from_slice(&["--rolls", "20", "--seed", "1"]);
        args.extend_from_slice(extra);
        let out = crate::helpers::dicephys(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stderr).contains("--preset laws")
    };
    // crosscheck runs under laws unless told otherwise (issue 46).
    assert!(!note("crosscheck", &["--com", "0,0,-4.5"]));
    assert!(note(
        "crosscheck",
        &["--com", "0,0,-4.5", "--preset", "split"]
    ));
    assert!(note(
        "crosscheck",
        &["--com", "0,0,-4.5", "--preset", "dicephys281"]
    ));
    assert!(!note(
        "crosscheck",
        &["--com", "0,0,-4.5", "--preset", "laws"]
    ));
    assert!(!note("crosscheck", &[]));
    assert!(note("roll", &["--com", "0,0,-1"]));
    assert!(note("fair", &["--com", "0,0,-1", "--engine", "rapier"]));
    assert!(!note("fair", &["--com", "0,0,-1", "--preset", "laws"]));
    assert!(!note("roll", &["--com", "0,0,-1", "--engine", "moreau"]));
    assert!(!note("roll", &["--pips", "3,1"]));
}

/// Coulomb's law for the centred cube flat on its −y face, sliding along x at v and spinning at
/// ω about the vertical, its four corners on the floor: the braking of the spin, dω/dt, at the
/// first instant (no yaw yet). Each corner i at (x_i, −h, z_i) from the centre (h = a/2) slips
/// at (v + ω z_i, −ω x_i) and carries friction μN_i against its slip; the weights N_i are those
/// that keep the cube from tipping (no angular acceleration about x or z: Σ x_i N_i = −h ΣF_x,
/// Σ z_i N_i = −h ΣF_z), found by iterating with the friction. The fourth unknown (the
/// weights' twist mode, ±γ on alternate corners) changes nothing at no yaw. To first order in
/// ω h / v this is −(3/2) μ g ω (1 − μ²) / v: the lateral friction of the heavier front corners
/// shifts weight sideways, whose lever on the sliding friction undoes μ² of the braking.
fn spin_braking(mu: f64, g: f64, v: f64, w: f64) -> f64 {
    let h = SIDE / 2.0;
    let corners = [(-h, -h), (-h, h), (h, -h), (h, h)];
    let mut n = [g / 4.0; 4];
    let mut torque = 0.0;
    for _ in 0..200 {
        let f: Vec<(f64, f64)> = corners
            .iter()
            .zip(&n)
            .map(|(&(x, z), &ni)| {
                let (ux, uz) = (v + w * z, -w * x);
                let u = ux.hypot(uz);
                (-mu * ni * ux / u, -mu * ni * uz / u)
            })
            .collect();
        let (fx, fz) = f.iter().fold((0.0, 0.0), |(a, b), &(x, z)| (a + x, b + z));
        let (pitch, roll) = (-h * fx / (4.0 * h * h), -h * fz / (4.0 * h * h));
        torque = corners
            .iter()
            .zip(&f)
            .map(|(&(x, z), &(fxi, fzi))| z * fxi - x * fzi)
            .sum();
        for (ni, &(x, z)) in n.iter_mut().zip(&corners) {
            *ni = g / 4.0 + pitch * x + roll * z;
        }
    }
    // Per unit mass: the moment about y over m a²/6.
    torque / (SIDE * SIDE / 6.0)
}

/// The first 1 ms step of the sliding, spinning cube on `kind` (v₀ 1 m/s, ω₀ 10 rad/s, μ 0.29,
/// touching the floor as it starts): (the spin's change per second, Coulomb's, the largest
/// rocking rate about a horizontal axis over the next 50 steps, ω/ω₀ after them).
fn sliding_and_spinning(kind: EngineKind) -> (f64, f64, f64, f64) {
    let (v0, w0, mu, dt) = (1.0, 10.0, 0.29, 0.001);
    let mut scene = cube(0.0, mu, scene_gravity(), dt);
    scene.restitution = 0.0;
    let mut engine = new_engine(kind, &scene).unwrap();
    engine
        .reset(&BodyState {
            linear_velocity: Vector3::new(v0, 0.0, 0.0),
            angular_velocity: Vector3::new(0.0, w0, 0.0),
            ..at_rest(
                Vector3::new(0.0, SIDE / 2.0 - 1e-9, 0.0),
                UnitQuaternion::identity(),
            )
        })
        .unwrap();
    engine.step().unwrap();
    let first = (engine.state().angular_velocity.y - w0) / dt;
    let mut rocking: f64 = 0.0;
    for _ in 1..50 {
        engine.step().unwrap();
        let w = engine.state().angular_velocity;
        rocking = rocking.max(w.x.abs()).max(w.z.abs());
    }
    let law = spin_braking(mu, scene.gravity, v0, w0);
    let end = engine.state().angular_velocity.y / w0;
    println!(
        "{kind:?}: first step dω/dt {first:.2} rad/s² against Coulomb's {law:.2} (first order \
         {:.2}); rocking up to {rocking:.3} rad/s; ω/ω₀ {end:.4} after 50 ms",
        -1.5 * mu * scene.gravity * w0 / v0 * (1.0 - mu * mu)
    );
    (first, law, rocking, end)
}

/// The exact limit: the spin's braking in the first step within 1 % of Coulomb's law at each
/// corner (−39.5 rad/s² here; a friction that brakes the spin apart from the slide, at μ N r,
/// would give −745). Bullet meets it (+0.6 %); Rapier 0.36.1's default friction model (one
/// constraint at the contact patch's centre and a twist) brakes it 19 times too hard, and is
/// pinned in `rapier_brakes_a_sliding_spin_at_once_and_bullet_rocks`.
#[test]
fn a_sliding_cube_s_spin_brakes_as_coulombs_law_says_on_bullet() {
    let (first, law, _, _) = sliding_and_spinning(EngineKind::Bullet);
    assert!(
        rel(first, law).abs() < 0.01,
        "Bullet: {first} against {law}"
    );
}

/// The same limit on Rapier, which does not meet it.
#[test]
#[ignore = "Rapier 0.36.1's default friction (FrictionModel::Simplified: one constraint at the \
            patch's centre and a twist) brakes a sliding die's spin 19 times harder than \
            Coulomb's law at its corners (issue 46, class N)"]
fn a_sliding_cube_s_spin_brakes_as_coulombs_law_says_on_rapier() {
    let (first, law, _, _) = sliding_and_spinning(EngineKind::Rapier);
    assert!(
        rel(first, law).abs() < 0.01,
        "Rapier: {first} against {law}"
    );
}

/// What each engine does over 50 ms, pinned so that an engine or a setting that changes it
/// shows. Rapier: the spin braked at ~19 times the law's rate, gone within 13 ms (ω/ω₀ below
/// 0.01 after 50 ms), the cube all but flat (below 0.05 rad/s about a horizontal axis).
/// Bullet: the law for a step, then the cube rocks on its corners (above 0.1 rad/s about a
/// horizontal axis): its contact manifold drops corners while the die slides (a plain box
/// meets the floor as the pair's second body, so each point is kept by where it touched the
/// floor, which the die leaves a millimetre a step, more than the 0.28 mm a point may drift; a
/// made die, keyed to itself, drops one some 16 steps on), the weight then rides on three
/// corners or fewer, and the spin is braked differently.
#[test]
fn rapier_brakes_a_sliding_spin_at_once_and_bullet_rocks() {
    let (_, _, rocking, end) = sliding_and_spinning(EngineKind::Rapier);
    assert!(
        end.abs() < 0.01 && rocking < 0.05,
        "Rapier: ω/ω₀ {end}, rocking {rocking}"
    );
    let (_, _, rocking, _) = sliding_and_spinning(EngineKind::Bullet);
    assert!(rocking > 0.1, "Bullet: rocking {rocking}");
}

/// Friction in an impact: the loaded cube, tilted 30° about x, lands on its lowest edge at V
/// while moving across the edge at 1 m/s (along z), μ 0.29, gravity off. With Newton's
/// restitution e and Coulomb's friction, sliding throughout (the slip keeps its sign: checked
/// below), the impulse is J_y = (1 + e) V / (K_yy − μ K_yz), J_z = −μ J_y, with K the edge's
/// inverse mass in the y–z plane (K_yy = 1/m + r_z²/I_x, K_yz = −r_y r_z/I_x): friction acts
/// on the whole impulse, the bounce's part included. Returns, for e, (Δv_y, Δv_z, ω'_x) after
/// one step beside the law's.
fn frictional_edge_impact(kind: EngineKind, preset: Preset, e: f64) -> ([f64; 3], [f64; 3]) {
    let (mu, w) = (0.29, 1.0);
    let mut scene = cube(COM_Z, mu, 0.0, 0.001);
    scene.restitution = e;
    scene.preset = preset;
    let hit = EdgeImpact::new(&scene, COM_Z, 30.0);
    let (m, i, ry, rz) = (hit.m, hit.ix, hit.r.y, hit.r.z);
    let (kyy, kyz) = (1.0 / m + rz * rz / i, -ry * rz / i);
    let jy = (1.0 + e) * V / (kyy - mu * kyz);
    let jz = -mu * jy;
    // The edge's slip after the impact, still along +z: sliding throughout.
    let slip = w + kyz * jy + (1.0 / m + ry * ry / i) * jz;
    assert!(slip > 0.0, "the law's slip reversed: {slip}");
    let law = [jy / m, jz / m, (ry * jz - rz * jy) / i];
    let mut engine = new_engine(kind, &scene).unwrap();
    engine
        .reset(&BodyState {
            linear_velocity: Vector3::new(0.0, -V, w),
            ..at_rest(Vector3::new(0.0, -hit.r.y - 1e-9, 0.0), hit.rotation)
        })
        .unwrap();
    engine.step().unwrap();
    let s = engine.state();
    let got = [
        s.linear_velocity.y + V,
        s.linear_velocity.z - w,
        s.angular_velocity.x,
    ];
    println!(
        "{kind:?} {preset:?} e {e}: Δv_y {:.4} (law {:.4}), Δv_z {:.4} (law {:.4}), ω'_x {:.2} (law {:.2})",
        got[0], law[0], got[1], law[1], got[2], law[2]
    );
    (got, law)
}

/// Bullet meets the frictional impact law within 1e-4, e = 0 and e = 0.5 (under the paper's
/// preset: touching as the step starts, so its Baumgarte term is nil).
#[test]
fn bullet_meets_the_frictional_impact_law() {
    for e in [0.0, 0.5] {
        let (got, law) = frictional_edge_impact(EngineKind::Bullet, Preset::Dicephys281, e);
        for k in 0..3 {
            assert!(
                rel(got[k], law[k]).abs() < 1e-4,
                "Bullet e {e}: {got:?} against {law:?}"
            );
        }
    }
}

/// The same law on Rapier at its best (`laws`: Coulomb's model, its bounce patched to carry
/// friction, each substep solved from nothing with three unbiased sweeps), within 1 %: at
/// e = 0 the compression alone, at e = 0.5 the bounce too. Warm-started with one sweep, as
/// Rapier ships, the normal impulse at e = 0 is 23 % over the law.
#[test]
fn rapier_meets_the_frictional_impact_law() {
    for e in [0.0, 0.5] {
        let (got, law) = frictional_edge_impact(EngineKind::Rapier, Preset::Laws, e);
        for k in 0..3 {
            assert!(
                rel(got[k], law[k]).abs() < 0.01,
                "Rapier e {e}: {got:?} against {law:?}"
            );
        }
    }
}

/// What Rapier does under every preset but `laws`, pinned: its friction impulse is the same
/// with a bounce as without (within 1e-3: the end-of-step restitution pass is normal only, as
/// Rapier 0.36.1 ships it for its default friction model), so at e = 0.5 it is 28 %
/// short of μ times the whole normal impulse; at e = 0 its normal impulse is 5–15 % above the
/// law's (measured 8.7 %; 4–10 % over its solver's settings: substeps, PGS iterations,
/// friction in the biased pass, the Coulomb model).
#[test]
fn rapier_bounces_without_friction() {
    let (plastic, law0) = frictional_edge_impact(EngineKind::Rapier, Preset::Dicephys281, 0.0);
    let (bouncy, law5) = frictional_edge_impact(EngineKind::Rapier, Preset::Dicephys281, 0.5);
    assert!(
        rel(bouncy[1], plastic[1]).abs() < 1e-3,
        "{bouncy:?} {plastic:?}"
    );
    assert!(
        rel(bouncy[1], law5[1]) < -0.2,
        "{bouncy:?} against {law5:?}"
    );
    let over = rel(plastic[0], law0[0]);
    assert!(
        (0.05..0.15).contains(&over),
        "Rapier e 0: Δv_y {over:+.3} off the law"
    );
}

/// Under `laws` (Rapier's Coulomb model, patched: vendor/rapier3d-f64/PATCH.md) the bounce
/// carries friction, and the friction is Coulomb's (against the slip, not the nearest point
/// of the cone to the block solve's impulse). While the edge slides, Coulomb's law makes the
/// friction impulse μ times the normal one, bounce included: Rapier's ratio is within 2 % of μ
/// at e = 0.5 (0.2 % measured; 5 % with the bounce patched alone, 19 % short unpatched), and
/// its friction impulse within 2 % of the law's (0.3 % short; 8 % and 25 %).
#[test]
fn rapier_under_laws_bounces_with_friction() {
    let (mu, e) = (0.29, 0.5);
    let (got, law) = frictional_edge_impact(EngineKind::Rapier, Preset::Laws, e);
    let ratio = -got[1] / got[0];
    assert!(
        (ratio / mu - 1.0).abs() < 0.02,
        "Rapier laws e {e}: friction/normal {ratio} against μ {mu}"
    );
    assert!(
        rel(got[1], law[1]).abs() < 0.02,
        "Rapier laws e {e}: {got:?} against {law:?}"
    );
}

/// A bounce's friction is not carried into the next step: warm-started, it would be applied
/// again to a corner that has left the floor, and the die would gain energy. Of 1,000 loaded
/// tumbles under `laws` on Rapier, 11 end a step with over 1 % more energy than they were
/// thrown with (22 of 1,000 upstream; 219 with the bounce's friction warm-started); asserted
/// at most 40.
#[test]
fn rapier_under_laws_gains_no_energy_from_its_bounces() {
    let out = crate::helpers::dicephys(&[
        "roll", "--engine", "rapier", "--preset", "laws", "--block", "16x16x16", "--com",
        "0,0,-4.5", "--throw", "tumble", "--rolls", "1000", "--seed", "1", "--json",
    ]);
    let doc = crate::helpers::json(&out);
    let gained = doc["energy_gain"].as_u64().unwrap();
    assert!(gained <= 40, "{gained} of 1000 throws gained energy");
}

/// The arbiter (`--engine moreau`: Moreau–Jean stepping with Newton's restitution and
/// Coulomb's friction solved at every touching corner) meets every closed form in this file
/// (the centre of mass fixed in free flight and the toppling threshold in the tests above,
/// the angular momentum and the sticking corner below), and these: the impulse law over an
/// edge (within 1e-6: the edge's two corners solved together), the frictional impact
/// law at e = 0 and 0.5 (within 1e-6: friction throughout the bounce), and Coulomb's braking
/// of a sliding spin (within 1 %), keeping the sliding cube flat (below 1e-3 rad/s).
#[test]
fn the_arbiter_meets_every_law_in_this_file() {
    let kind = EngineKind::Moreau;
    for (com_z, theta) in [(COM_Z, 45.0), (COM_Z, -45.0), (COM_Z, 30.0), (0.0, 30.0)] {
        let scene = cube(com_z, 0.0, 0.0, 0.001);
        let mut engine = new_engine(kind, &scene).unwrap();
        let hit = EdgeImpact::new(&scene, com_z, theta);
        let s = hit.after(engine.as_mut(), -1e-9);
        let got = (s.linear_velocity.y + V, s.angular_velocity.x);
        println!(
            "Moreau com {com_z} {theta}°: {got:?} against {:?}",
            hit.law()
        );
        assert_meets_law(&format!("Moreau {theta}°"), got, hit.law(), 1e-6);
        assert!(tip_across_the_edge(&s) < 1e-6, "{s:?}");
    }

    for e in [0.0, 0.5] {
        let (got, law) = frictional_edge_impact(kind, Preset::Dicephys281, e);
        for k in 0..3 {
            assert!(
                rel(got[k], law[k]).abs() < 1e-6,
                "e {e}: {got:?} against {law:?}"
            );
        }
    }

    let (first, law, rocking, _) = sliding_and_spinning(kind);
    assert!(rel(first, law).abs() < 0.01, "{first} against {law}");
    assert!(rocking < 1e-3, "rocking {rocking}");
}

/// The loaded cube's angular momentum and rotational energy after `steps` steps of `dt` in
/// free flight (gravity off), spinning at (30, −50, 80) rad/s about no principal axis, each
/// relative to its start: (|ΔL|/|L|, ΔE/E).
fn torque_free(kind: EngineKind, preset: Preset, dt: f64, steps: usize) -> (f64, f64) {
    let mut scene = cube(COM_Z, 0.29, 0.0, dt);
    scene.preset = preset;
    let inertia = MassProps::of(&scene).unwrap().inertia;
    let start = BodyState {
        angular_velocity: Vector3::new(30.0, -50.0, 80.0),
        ..at_rest(
            Vector3::new(0.0, 0.5, 0.0),
            UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1),
        )
    };
    let momentum =
        |s: &BodyState| s.rotation * (inertia * (s.rotation.inverse() * s.angular_velocity));
    let energy = |s: &BodyState| 0.5 * s.angular_velocity.dot(&momentum(s));
    let mut engine = new_engine(kind, &scene).unwrap();
    engine.reset(&start).unwrap();
    for _ in 0..steps {
        engine.step().unwrap();
    }
    let s = engine.state();
    let dl = (momentum(&s) - momentum(&start)).norm() / momentum(&start).norm();
    let de = energy(&s) / energy(&start) - 1.0;
    println!(
        "{kind:?} {preset:?} dt {dt}: |ΔL|/|L| {dl:.2e}, ΔE/E {de:+.2e}, ω {:?}",
        s.angular_velocity
    );
    (dl, de)
}

/// Euler's equations, torque-free: a body whose moments differ keeps its angular momentum in
/// the world and its energy, while its angular velocity wanders (the loaded cube's moments are
/// 22.4, 22.4 and 42.7 m mm²). Over 0.1 s: the arbiter keeps L to 1e-9 and E to 1e-4 (1.4e-5
/// measured: its splitting is second order, without drift) at 1 ms; Rapier's
/// gyroscopic pass (first order) L within 1 %; Bullet under `laws` (its implicit gyroscopic
/// impulse, first order and damping) within 2 % at 1 ms and 0.2 % at 0.1 ms. Under every
/// other preset Bullet keeps ω itself constant (to 1e-12), so that L turns with the body (33 %
/// here): 2.81 had no gyroscopic term, and 3.24's (the `bullet3` preset's) is dropped for a
/// body as small as a die — btMatrix3x3::solve33 divides by det J only above DBL_EPSILON, and
/// a die's J is ~1e-21 kg³ m⁶.
#[test]
fn a_loaded_cube_keeps_its_angular_momentum_in_flight() {
    use EngineKind::{Bullet, Moreau, Rapier};
    let (dl, de) = torque_free(Moreau, Preset::Dicephys281, 0.001, 100);
    assert!(dl < 1e-9 && de.abs() < 1e-4, "Moreau: {dl} {de}");
    let (dl, _) = torque_free(Rapier, Preset::Dicephys281, 0.001, 100);
    assert!(dl < 0.01, "Rapier: {dl}");
    let (dl, _) = torque_free(Bullet, Preset::Laws, 0.001, 100);
    assert!(dl < 0.02, "Bullet laws at 1 ms: {dl}");
    let (dl, _) = torque_free(Bullet, Preset::Laws, 0.0001, 1000);
    assert!(dl < 0.002, "Bullet laws at 0.1 ms: {dl}");
    for preset in [Preset::Dicephys281, Preset::Split, Preset::Bullet3] {
        let (dl, de) = torque_free(Bullet, preset, 0.001, 100);
        assert!(dl > 0.3 && de.abs() < 1e-12, "Bullet {preset:?}: {dl} {de}");
    }
}

/// The loaded cube turned so that one corner is lowest: its rotation, and that corner from the
/// centre of mass.
fn lowest_corner() -> (UnitQuaternion<f64>, Vector3<f64>) {
    let rotation = UnitQuaternion::from_euler_angles(0.5, 0.0, 0.35);
    let com = Vector3::new(0.0, 0.0, COM_Z);
    let r = (0..8)
        .map(|k| {
            let sign = |bit: u32| if k & (1 << bit) == 0 { -1.0 } else { 1.0 };
            rotation * (Vector3::new(sign(0), sign(1), sign(2)) * (SIDE / 2.0) - com)
        })
        .min_by(|a, b| a.y.total_cmp(&b.y))
        .unwrap();
    (rotation, r)
}

/// One step of `kind` from the cube at `rotation` with its corner `r` just touching the floor,
/// moving at `v`: the state after it.
fn land_on_corner(
    kind: EngineKind,
    scene: &Scene,
    (rotation, r): (UnitQuaternion<f64>, Vector3<f64>),
    v: Vector3<f64>,
) -> BodyState {
    let mut engine = new_engine(kind, scene).unwrap();
    engine
        .reset(&BodyState {
            linear_velocity: v,
            ..at_rest(Vector3::new(0.0, -r.y - 1e-9, 0.0), rotation)
        })
        .unwrap();
    engine.step().unwrap();
    engine.state()
}

/// Friction in Coulomb's cone: the loaded cube, turned so that one corner is lowest, lands on
/// it at V while sliding at 0.3 m/s along z, e = 0, μ = 1. The corner sticks (checked: the
/// law's friction lies inside the cone), so the impulse is the one that stops the corner dead
/// in all three directions, J = −K⁻¹ u, with K the corner's inverse mass (1/m − [r]× I⁻¹ [r]×)
/// and u its velocity: its part across the slip (along x) is not nil, since the lever couples
/// the directions. The arbiter meets it (Δv within 1e-3 of J/m: 1e-12 measured), Bullet under
/// `laws` within 2 % (1.0 % short: ten solver iterations). Bullet's other presets (one friction
/// row per point, along the slip) put nothing across the slip and fall 22 % short along the
/// normal. Rapier overshoots the normal impulse by default (24 %): each substep warm-starts
/// from the last, which applies the impact's impulse again, and its one unbiased sweep a
/// substep undoes it only in part (36 % over under `laws` so); under `laws` each substep is
/// solved from nothing, with three sweeps: within 1 % (0.4 % measured).
fn sticking_corner(kind: EngineKind, preset: Preset) -> (Vector3<f64>, Vector3<f64>) {
    let mut scene = cube(COM_Z, 1.0, 0.0, 0.001);
    scene.restitution = 0.0;
    scene.preset = preset;
    let mp = MassProps::of(&scene).unwrap();
    let (rotation, r) = lowest_corner();
    let iw = rotation.to_rotation_matrix() * mp.inertia * rotation.to_rotation_matrix().transpose();
    let k = Matrix3::identity() / mp.mass
        - r.cross_matrix() * iw.try_inverse().unwrap() * r.cross_matrix();
    let v = Vector3::new(0.0, -V, 0.3);
    let j = -(k.try_inverse().unwrap() * v);
    let tangent = (j.x * j.x + j.z * j.z).sqrt();
    assert!(
        tangent < 0.9 * j.y,
        "the law's friction leaves the cone: {j:?}"
    );
    let got = land_on_corner(kind, &scene, (rotation, r), v).linear_velocity - v;
    println!(
        "{kind:?} {preset:?}: Δv {got:?} against the law's {:?}",
        j / mp.mass
    );
    (got, j / mp.mass)
}

#[test]
fn a_corner_that_sticks_stops_dead_in_every_direction() {
    for (kind, preset, tol) in [
        (EngineKind::Moreau, Preset::Dicephys281, 1e-3),
        (EngineKind::Bullet, Preset::Laws, 0.02),
        (EngineKind::Rapier, Preset::Laws, 0.01),
    ] {
        let (got, law) = sticking_corner(kind, preset);
        assert!(
            (got - law).norm() < tol * law.norm(),
            "{kind:?} {preset:?}: Δv {got:?} against {law:?}"
        );
    }
    let (got, law) = sticking_corner(EngineKind::Bullet, Preset::Split);
    assert!(
        law.x.abs() > 0.05 * law.norm(),
        "the law's cross-slip part: {law:?}"
    );
    assert!(
        got.x.abs() < 0.01 * law.x.abs(),
        "Bullet: {got:?} against {law:?}"
    );
    assert!(got.y < 0.9 * law.y, "Bullet: {got:?} against {law:?}");
    let (got, law) = sticking_corner(EngineKind::Rapier, Preset::Dicephys281);
    assert!(got.y > 1.1 * law.y, "Rapier: {got:?} against {law:?}");
}

/// Coulomb's cone on a sliding corner: the loaded cube lands on its lowest corner (turned as
/// in `sticking_corner`) at V while sliding at 1.5 m/s along z, e = 0, μ = 0.29, gravity off.
/// The corner slides through the impact, so the law puts the friction on the cone's surface,
/// |J_t| = μ J_n, against the corner's slip as the step ends (the discrete law of maximal
/// dissipation). J = m Δv; the slip after, u' = v' + ω' × r, with r the corner from the
/// centre of mass as the step starts (where the solvers take it). Returns |J_t|/(μ J_n) and
/// the angle, in degrees, between −J_t and u'.
fn sliding_corner(kind: EngineKind, preset: Preset) -> (f64, f64) {
    let mu = 0.29;
    let mut scene = cube(COM_Z, mu, 0.0, 0.001);
    scene.restitution = 0.0;
    scene.preset = preset;
    let mp = MassProps::of(&scene).unwrap();
    let (rotation, r) = lowest_corner();
    let v = Vector3::new(0.0, -V, 1.5);
    let s = land_on_corner(kind, &scene, (rotation, r), v);
    let j = (s.linear_velocity - v) * mp.mass;
    let jt = Vector3::new(j.x, 0.0, j.z);
    let u = s.linear_velocity + s.angular_velocity.cross(&r);
    let slip = Vector3::new(u.x, 0.0, u.z);
    let angle = (-jt).angle(&slip).to_degrees();
    println!(
        "{kind:?} {preset:?}: |J_t|/(μ J_n) {:.4}, angle to the slip {angle:.2}°, slip after {:.3} m/s",
        jt.norm() / (mu * j.y),
        slip.norm()
    );
    (jt.norm() / (mu * j.y), angle)
}

#[test]
fn a_sliding_corner_s_friction_lies_on_coulombs_cone_against_its_slip() {
    // Each within 1 % of the cone and 2° of the slip. The arbiter: on the cone to 1e-12,
    // 1.4° off the slip as the step ends (the die's free turn after the impulses changes ω).
    // Bullet under `laws`: 0.0°; it was 13.6 % outside the cone and 28° off the slip when each
    // of its two friction rows was held to μ J_n on its own (a square, not a disc), and 25.8°
    // off with the pair scaled back onto the disc afterwards. Rapier under `laws`: 0.5° (1.4°
    // with one sweep a substep, warm-started); it was 6.8° off when its block solve's impulse
    // was scaled onto the disc (upstream).
    for (kind, preset) in [
        (EngineKind::Moreau, Preset::Dicephys281),
        (EngineKind::Bullet, Preset::Laws),
        (EngineKind::Rapier, Preset::Laws),
    ] {
        let (ratio, angle) = sliding_corner(kind, preset);
        assert!(
            (ratio - 1.0).abs() < 0.01 && angle < 2.0,
            "{kind:?} {preset:?}: |J_t|/(μ J_n) {ratio}, {angle}° off the slip"
        );
    }
}

/// Issue 72, a contact's bounce threshold: the centred cube falling flat at speed v onto the
/// floor (gravity off, split preset, so the bounce is exact) leaves at e v where v is above
/// the threshold and at rest where it is below, as Bullet's restitution curve says; 0 is
/// today's contact, every impact bouncing.
#[test]
fn a_bounce_threshold_stops_the_slow_impacts_and_keeps_the_fast() {
    for (v, threshold, want) in [
        (0.3, 0.0, E * 0.3),
        (0.3, 0.2, E * 0.3),
        (0.3, 0.4, 0.0),
        (1.5, 1.0, E * 1.5),
        (0.9, 1.0, 0.0),
    ] {
        let mut scene = cube(0.0, 0.0, 0.0, 0.001);
        scene.preset = Preset::Split;
        scene.bounce_threshold = threshold;
        let mut engine = new_engine(EngineKind::Bullet, &scene).unwrap();
        engine
            .reset(&BodyState {
                linear_velocity: Vector3::new(0.0, -v, 0.0),
                ..at_rest(
                    Vector3::new(0.0, SIDE / 2.0 + 1e-4, 0.0),
                    UnitQuaternion::identity(),
                )
            })
            .unwrap();
        for _ in 0..20 {
            engine.step().unwrap();
        }
        let up = engine.state().linear_velocity.y;
        assert!(
            (up - want).abs() < 1e-4 * v,
            "v {v} m/s, threshold {threshold}: leaves at {up} m/s, the law {want}"
        );
    }
    // Rapier and the arbiter have none: refused in one line, naming the flag.
    let o = super::helpers::dicephys(&[
        "roll",
        "--engine",
        "rapier",
        "--bounce-threshold",
        "0.2",
        "--rolls",
        "2",
    ]);
    super::helpers::refused(&o, 2, "--bounce-threshold");
}

/// The soft contact's landing: the centred cube falling flat at v (gravity off) onto a table
/// of contact time τ and restitution e, at a step of τ/`steps`. Returns the speed it leaves
/// at over v and how long its velocity changed, s.
fn soft_landing(preset: Preset, e: f64, tau: f64, v: f64, steps: f64) -> (f64, f64) {
    let mut scene = cube(0.0, 0.5, 0.0, tau / steps);
    scene.preset = preset;
    scene.restitution = e;
    scene.contact_time = tau;
    scene.validate(false).unwrap();
    let mut engine = new_engine(EngineKind::Bullet, &scene).unwrap();
    engine
        .reset(&BodyState {
            linear_velocity: Vector3::new(0.0, -v, 0.0),
            ..at_rest(
                Vector3::new(0.0, SIDE / 2.0 + 1e-5, 0.0),
                UnitQuaternion::identity(),
            )
        })
        .unwrap();
    let (mut first, mut last, mut before) = (None, 0, -v);
    for n in 1..=(4.0 * steps) as usize {
        engine.step().unwrap();
        let now = engine.state().linear_velocity.y;
        if (now - before).abs() > 1e-12 {
            first.get_or_insert(n);
            last = n;
        }
        before = now;
    }
    let steps_in_contact = last + 1 - first.expect("it never touched");
    (before / v, steps_in_contact as f64 * scene.dt)
}

/// Issue 72, a soft contact (`model::compliance`): a cube landing flat leaves at e times its
/// speed after the contact time τ, whatever the speed (the spring and dashpot are linear),
/// under the presets that split the penetration off as under DicePhys's (a soft contact's
/// spring acts in the velocity solve under both). Bullet solves it by backward Euler, whose
/// own damping vanishes with the step: at τ/1000 within 1 % of e and of τ. At the fits' step
/// (τ/5) it keeps less, which the results page reports; 0 is today's rigid contact.
#[test]
fn a_soft_contact_lands_a_flat_die_as_the_spring_and_dashpot_say() {
    for (preset, e, tau, v) in [
        (Preset::Dicephys281, 0.5, 0.005, 1.0),
        (Preset::Dicephys281, 0.5, 0.005, 2.0),
        (Preset::Dicephys281, 0.2, 0.005, 1.0),
        (Preset::Dicephys281, 0.8, 0.002, 1.0),
        (Preset::Dicephys281, 0.05, 0.01, 1.0),
        (Preset::Split, 0.5, 0.005, 1.0),
    ] {
        let (got, time) = soft_landing(preset, e, tau, v, 1000.0);
        assert!(
            (got - e).abs() < 0.01 * e,
            "{preset:?}, e {e}, τ {tau} s, v {v} m/s: leaves at {got} v"
        );
        assert!(
            (time - tau).abs() < 0.01 * tau,
            "{preset:?}, e {e}, τ {tau} s, v {v} m/s: lasts {time} s"
        );
    }
    // Rapier and the arbiter have none: refused in one line, naming the flag; too short a
    // contact for the step is refused too.
    for (engine, ms) in [("rapier", "5"), ("bullet", "1")] {
        let o = super::helpers::dicephys(&[
            "roll",
            "--engine",
            engine,
            "--contact-time",
            ms,
            "--rolls",
            "2",
        ]);
        super::helpers::refused(&o, 2, "--contact-time");
    }
}

/// Issue 72: on a soft table the early stop (the certificate) names the face every step's rest
/// rule does, throw for throw. A die pressed into the table holds energy in its springs that
/// they give back; counted without it, the certificate fired at the deepest point of an
/// impact and was wrong on 13 of these 2,000 throws.
#[test]
fn on_a_soft_table_the_early_stop_names_what_every_step_does() {
    let dir = super::helpers::Scratch::new("soft-certificate");
    let outcomes = |settle: &str| {
        let file = dir.join(format!("{settle}.csv"));
        let o = super::helpers::dicephys(&[
            "roll",
            "--block",
            "16x16x16",
            "--throw",
            "tumble",
            "--contact-time",
            "5",
            "--restitution",
            "0.8",
            "--rolls",
            "2000",
            "--seed",
            "1",
            "--settle",
            settle,
            "--per-roll",
            file.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(&file).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let at = header.iter().position(|h| *h == "outcome").unwrap();
        lines
            .map(|l| l.split(',').nth(at).unwrap().to_string())
            .collect::<Vec<_>>()
    };
    let (early, full) = (outcomes("certificate"), outcomes("dicephys"));
    assert_eq!(early.len(), 2000);
    let differ = early.iter().zip(&full).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "{differ} of 2000 throws named otherwise");
}

/// Issue 72's fifth round, a rounded mesh (`Shape::rounded`): each engine collides the die the
/// model's geometry describes (the inner body's hull swept by the radius: Bullet's hull margin,
/// Rapier's round hull). V1 rounded 2 mm, dropped from 0.5 mm onto its lowest corner at a step
/// of 0.1 ms (e 0), is first stopped with its lowest point, as `DieBody::lowest_point`
/// computes it, between 0.1 r below the floor and 0.05 r above it, and comes to rest on a face
/// within 0.05 r of it. Measured: Bullet stops the corner 134 µm deep (it finds a large
/// margin's contact late, six steps at this speed; 66 µm at r = 1 mm) and rests at 0; Rapier
/// stops it at 0 and rests 56 µm deep (its own allowed penetration, 73 µm for the sharp die).
/// The sharp die's corner reaches 0.30 mm (0.15 r) lower in this turn, and the inner body
/// without its radius 2 mm: either would fail.
#[test]
fn a_rounded_mesh_touches_the_floor_where_its_geometry_says_on_both_engines() {
    use dicephys::model::die::DieBody;
    use dicephys::model::shape::{from_mesh, Reads};
    let bytes = include_bytes!("../data/hendecahedron_v1.obj");
    let mesh = dicephys::model::mesh_file::read_mesh(bytes, "v1").unwrap();
    let sharp = from_mesh(&mesh.scaled(14.821972), "v1".into(), None, Reads::Down).unwrap();
    let r = 0.002;
    let rounded = sharp.rounded(r).unwrap();
    let turn = UnitQuaternion::from_euler_angles(0.7, 0.4, 0.2);
    let scene_of = |shape| {
        let mut s = Scene::paper_shape(shape, Mode::ThreeD);
        s.dt = 1e-4;
        s.restitution = 0.0;
        s.friction = 1.0;
        s.validate(false).unwrap();
        s
    };
    let scene = scene_of(rounded);
    let die = DieBody::of(&scene);
    let probe = at_rest(Vector3::zeros(), turn);
    let reach = -die.lowest_point(&probe);
    let sharp_reach = -DieBody::of(&scene_of(sharp)).lowest_point(&probe);
    assert!(
        sharp_reach - reach > 0.1 * r,
        "{sharp_reach} against {reach}"
    );
    for engine in [EngineKind::Bullet, EngineKind::Rapier] {
        let mut e = new_engine(engine, &scene).unwrap();
        e.reset(&at_rest(Vector3::new(0.0, reach + 5e-4, 0.0), turn))
            .unwrap();
        let mut first = None;
        let mut before = 0.0;
        for n in 0..20_000 {
            e.step().unwrap();
            let s = e.state();
            // Free fall gains g dt a step; the first step that gains less has touched.
            let gained = before - s.linear_velocity.y;
            if first.is_none() && n > 0 && gained < 0.5 * scene.gravity * scene.dt {
                first = Some(die.lowest_point(&s));
            }
            before = s.linear_velocity.y;
        }
        let touched = first.expect("it never touched");
        let rest = die.lowest_point(&e.state());
        assert!(
            (-0.1 * r..0.05 * r).contains(&touched) && rest.abs() < 0.05 * r,
            "{engine:?}: first stopped {touched} m, at rest {rest} m from the floor"
        );
    }
}
