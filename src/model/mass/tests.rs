use super::*;
use crate::error::Error;
use crate::model::block::{Block, Mode};
use crate::model::faces::Layout;
use crate::model::scene::Scene;
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

fn cube_scene(side_mm: f64) -> Scene {
    let b = Block::from_mm(side_mm, side_mm, side_mm).unwrap();
    Scene::paper(b, Mode::ThreeD)
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn a_rounded_box_is_a_box_at_radius_zero_and_a_ball_at_the_largest() {
    let a = Vector3::new(0.012, 0.010, 0.07);
    let (v, s) = rounded_box(&a, 0.0);
    assert!(rel(v, 8.0 * a.x * a.y * a.z) < 1e-15);
    for i in 0..3 {
        // ∫xᵢ² dV = V aᵢ²/3.
        assert!(rel(s[i], v * a[i] * a[i] / 3.0) < 1e-14);
    }
    let r = 0.008;
    let (v, s) = rounded_box(&Vector3::repeat(r), r);
    assert!(rel(v, 4.0 * PI * r.powi(3) / 3.0) < 1e-15);
    for i in 0..3 {
        assert!(rel(s[i], 4.0 * PI * r.powi(5) / 15.0) < 1e-14);
    }
}

#[test]
fn a_rounded_box_matches_a_fine_quadrature() {
    // A midpoint sum over a fine grid of the inside test: slow but independent.
    let a = Vector3::new(0.008, 0.007, 0.006);
    let r = 0.002;
    let (v, s) = rounded_box(&a, r);
    let n = 240;
    let (mut qv, mut qs) = (0.0, Vector3::zeros());
    let h = a * 2.0 / n as f64;
    for ix in 0..n {
        for iy in 0..n {
            for iz in 0..n {
                let p = Vector3::new(
                    -a.x + (ix as f64 + 0.5) * h.x,
                    -a.y + (iy as f64 + 0.5) * h.y,
                    -a.z + (iz as f64 + 0.5) * h.z,
                );
                let out = (p.abs() - a.map(|x| x - r)).map(|x| x.max(0.0)).norm();
                if out <= r {
                    let dv = h.x * h.y * h.z;
                    qv += dv;
                    qs += p.component_mul(&p) * dv;
                }
            }
        }
    }
    // The grid resolves the curved boundary to about h/a ≈ 1/n in volume.
    assert!(rel(qv, v) < 2e-3, "{qv} {v}");
    for i in 0..3 {
        assert!(rel(qs[i], s[i]) < 3e-3, "{i}");
    }
}

#[test]
fn a_caps_moments_are_the_textbook_ones() {
    for (d, h) in [
        (0.003, 0.0015),
        (0.003, 0.0005),
        (0.002, 0.00001),
        (0.004, 0.001),
    ] {
        let p = Pips {
            diameter: d,
            depth: h,
            shape: PipShape::Cap,
            fill_density: 0.0,
            spacing: 0.25,
        };
        let [v, z1, z2, u2] = cavity(&p);
        let rho = ((d / 2.0) * (d / 2.0) + h * h) / (2.0 * h);
        // V = πh²(3ρ − h)/3; centroid 3(2ρ − h)²/(4(3ρ − h)) from the ball's centre.
        let want_v = PI * h * h * (3.0 * rho - h) / 3.0;
        assert!(rel(v, want_v) < 1e-12, "{d} {h}");
        let from_centre = 3.0 * (2.0 * rho - h).powi(2) / (4.0 * (3.0 * rho - h));
        // z is measured inward from the face, which is ρ − h from the ball's centre.
        assert!(rel(z1 / v, from_centre - (rho - h)) < 1e-9, "{d} {h}");
        let _ = (z2, u2);
    }
    // A hemisphere: about the centre of its flat face, ∫(u² + w²) dV = (2/5) V ρ² (half a
    // ball's), and ∫z² dV = ∫u² dV = V ρ²/5.
    let r = 0.0015;
    let p = Pips {
        diameter: 2.0 * r,
        depth: r,
        shape: PipShape::Cap,
        fill_density: 0.0,
        spacing: 0.25,
    };
    let [v, _, z2, u2] = cavity(&p);
    assert!(rel(v, 2.0 * PI * r.powi(3) / 3.0) < 1e-14);
    assert!(rel(z2, v * r * r / 5.0) < 1e-13);
    assert!(rel(u2, v * r * r / 5.0) < 1e-13);
    // A cylinder: V = π a² h, ∫z dV = V h/2, ∫z² dV = V h²/3, ∫u² dV = V a²/4.
    let p = Pips {
        diameter: 0.003,
        depth: 0.001,
        shape: PipShape::Cylinder,
        fill_density: 0.0,
        spacing: 0.25,
    };
    let [v, z1, z2, u2] = cavity(&p);
    let a = 0.0015;
    assert!(rel(v, PI * a * a * 0.001) < 1e-14);
    assert!(rel(z1, v * 0.0005) < 1e-14);
    assert!(rel(z2, v * 1e-6 / 3.0) < 1e-13);
    assert!(rel(u2, v * a * a / 4.0) < 1e-13);
}

#[test]
fn a_plain_die_has_the_boxes_mass_properties_and_a_moved_centre_the_parallel_axes() {
    let mut s = cube_scene(16.0);
    let plain = MassProps::of(&s).unwrap();
    assert!(plain.aligned() && plain.com == Vector3::zeros());
    // Rounded with radius 0 by the general path: the same to rounding.
    s.features.com = Some([0.0, 0.0, 0.0]);
    let general = MassProps::of(&s).unwrap();
    assert!(rel(general.mass, plain.mass) < 1e-15);
    for i in 0..3 {
        assert!(rel(general.moments[i], plain.moments[i]) < 1e-14);
    }
    // A centre 2 mm down z: I_xx and I_yy less m c², I_zz unchanged, axes kept.
    s.features.com = Some([0.0, 0.0, -0.002]);
    let moved = MassProps::of(&s).unwrap();
    assert!(moved.aligned());
    let m = plain.mass;
    assert!(rel(moved.moments.x, plain.moments.x - m * 4e-6) < 1e-14);
    assert!(rel(moved.moments.z, plain.moments.z) < 1e-14);
}

/// Overlapping pips (reliability round 5, class C), against an independent integral: one
/// random point in each cell of a 160³ grid over the whole 16 mm cube (stratified, so
/// that no lattice lines up with the pips' circles; ~5e-5 of the mass at 1σ), each kept
/// unless inside a pip, the cavities written out here from their description (a cylinder,
/// or a ball's cap below each pip's circle). Deep cylinders meeting in threes at the corners lose 3.5 % of the
/// cube counted twice; caps at a wide spacing, 0.07 %.
#[test]
fn overlapping_pips_take_away_their_union() {
    for (shape, d, h, spacing) in [
        (PipShape::Cylinder, 0.003, 0.005, 0.25),
        (PipShape::Cap, 0.0016, 0.0008, 0.45),
    ] {
        let mut s = cube_scene(16.0);
        let p = Pips {
            diameter: d,
            depth: h,
            shape,
            fill_density: 0.0,
            spacing,
        };
        s.features.pips = Some(p);
        let m = MassProps::of(&s).unwrap();
        let half = Vector3::repeat(0.008);
        let places = pip_places(&half, &p, Layout::Right);
        let rho_ball = (0.25 * d * d + h * h) / (2.0 * h);
        let hollow = |x: &Vector3<f64>| {
            places.iter().any(|&(i, sign, pj, pk)| {
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                let depth = 0.008 - sign * x[i];
                let r2 = (x[j] - pj).powi(2) + (x[k] - pk).powi(2);
                (0.0..=h).contains(&depth)
                    && match shape {
                        PipShape::Cylinder => r2 <= 0.25 * d * d,
                        // The ball's centre ρ beyond the pip's bottom, inward.
                        PipShape::Cap => {
                            r2 + (depth - (h - rho_ball)).powi(2) <= rho_ball * rho_ball
                        }
                    }
            })
        };
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let n = 160;
        let cell = 0.016 / n as f64;
        let (mut mass, mut first, mut second) = (0.0, Vector3::zeros(), Matrix3::zeros());
        for c in 0..n * n * n {
            let x = Vector3::new(c % n, (c / n) % n, c / (n * n))
                .map(|i| (i as f64 + rng.random::<f64>()) * cell - 0.008);
            if !hollow(&x) {
                let w = s.density * cell.powi(3);
                mass += w;
                first += x * w;
                second += x * x.transpose() * w;
            }
        }
        let com = first / mass;
        let about = Matrix3::identity() * second.trace() - second;
        let inertia =
            about - mass * (Matrix3::identity() * com.norm_squared() - com * com.transpose());
        // About 4σ of the stratified sum.
        assert!(
            rel(m.mass, mass) < 2e-4,
            "{shape:?}: {} against {mass}",
            m.mass
        );
        assert!(
            (m.com - com).norm() < 2e-6,
            "{shape:?}: {:?} against {com:?}",
            m.com
        );
        assert!(
            (m.inertia - inertia).norm() < 1e-3 * inertia.norm(),
            "{shape:?}: {} against {}",
            m.inertia,
            inertia
        );
        let counted_twice = s.mass() - 21.0 * cavity(&p)[0] * s.density;
        assert!(
            mass > counted_twice,
            "{shape:?}: the overlaps are there to give back"
        );
    }
}

#[test]
fn pips_lighten_the_die_by_their_volume_and_move_its_centre_toward_one() {
    let mut s = cube_scene(16.0);
    let p = Pips {
        diameter: 0.003,
        depth: 0.001,
        shape: PipShape::Cap,
        fill_density: 0.0,
        spacing: 0.25,
    };
    s.features.pips = Some(p);
    let m = MassProps::of(&s).unwrap();
    let v = cavity(&p)[0];
    let solid = s.mass();
    assert!(rel(m.mass, solid - 21.0 * v * s.density) < 1e-14);
    // Face n has n pips: the centre of mass moves toward the faces with fewer, each axis
    // by (pips on − face − pips on + face) × V × (h − z̄) / m... in sign: toward 1 (+z),
    // 2 (+x), 3 (+y), the faces opposite 6, 5, 4.
    assert!(
        m.com.x > 0.0 && m.com.y > 0.0 && m.com.z > 0.0,
        "{:?}",
        m.com
    );
    let [vv, z1, _, _] = cavity(&p);
    let h = 0.008;
    // Along z: 1 pip on +z, 6 on −z: Σ m x = −ρ (1·(h V − z̄V) − 6·(h V − z̄V)).
    let want_z = s.density * 5.0 * (h * vv - z1) / m.mass;
    assert!(rel(m.com.z, want_z) < 1e-12, "{} {want_z}", m.com.z);
    // The diagonal pips of 2 and 3 tilt the principal frame off the body axes.
    assert!(!m.aligned());
    let back = m.principal.to_rotation_matrix().matrix()
        * Matrix3::from_diagonal(&m.moments)
        * m.principal.to_rotation_matrix().matrix().transpose();
    assert!((back - m.inertia).norm() < 1e-12 * m.inertia.norm());
    // Filled with the die's own density, nothing is drilled.
    s.features.pips = Some(Pips {
        fill_density: s.density,
        ..p
    });
    let full = MassProps::of(&s).unwrap();
    assert!(rel(full.mass, solid) < 1e-15 && full.com.norm() < 1e-18);
}

#[test]
fn an_insert_moves_the_centre_and_the_moments_as_two_boxes_do() {
    // A 16 mm cube (a = 8 mm half side) of density ρ with a cube of side b = 4 mm and
    // density ρ' at c = (0, 0, −4 mm): in closed form, with Δ = (ρ' − ρ) b³,
    // m = ρ (2a)³ + Δ, z̄ = Δ c / m, and about the geometric centre
    // I_xx = ρ (2a)⁵/6 + Δ (b²/6 + c²), I_zz = ρ (2a)⁵/6 + Δ b²/6; about the centre of mass
    // I_xx − m z̄², I_zz unchanged.
    let mut s = cube_scene(16.0);
    let (rho, rho2, side, b, c) = (s.density, 19300.0, 0.016, 0.004, -0.004);
    s.features.insert = Some(Insert {
        size: [b; 3],
        centre: [0.0, 0.0, c],
        density: rho2,
    });
    let m = MassProps::of(&s).unwrap();
    let delta = (rho2 - rho) * b * b * b;
    let mass = rho * side * side * side + delta;
    let zbar = delta * c / mass;
    let ixx = rho * side.powi(5) / 6.0 + delta * (b * b / 6.0 + c * c) - mass * zbar * zbar;
    let izz = rho * side.powi(5) / 6.0 + delta * b * b / 6.0;
    assert!(rel(m.mass, mass) < 1e-14, "{} {mass}", m.mass);
    assert!(rel(m.com.z, zbar) < 1e-13 && m.com.x == 0.0 && m.com.y == 0.0);
    assert!(m.aligned());
    assert!(rel(m.moments.x, ixx) < 1e-13 && rel(m.moments.y, ixx) < 1e-13);
    assert!(rel(m.moments.z, izz) < 1e-13);
    // Of the die's own density: the plain cube.
    s.features.insert = Some(Insert {
        density: rho,
        ..s.features.insert.unwrap()
    });
    let same = MassProps::of(&s).unwrap();
    assert!(rel(same.mass, rho * side.powi(3)) < 1e-15 && same.com.norm() < 1e-18);
    // Off every axis: the principal frame turns off the body's.
    s.features.insert = Some(Insert {
        size: [b; 3],
        centre: [0.001, 0.001, c],
        density: rho2,
    });
    assert!(!MassProps::of(&s).unwrap().aligned());
}

#[test]
fn an_inertia_given_outright_is_the_bodys() {
    let mut s = cube_scene(16.0);
    // A tensor with a product of inertia: its principal moments are its eigenvalues.
    let t = [2.2e-7, 2.0e-7, 1.8e-7, 0.1e-7, 0.0, 0.0];
    s.features.inertia = Some(t);
    let m = MassProps::of(&s).unwrap();
    assert_eq!(m.inertia[(0, 1)], 0.1e-7);
    assert_eq!(m.inertia[(2, 2)], 1.8e-7);
    let mut moments: Vec<f64> = m.moments.iter().copied().collect();
    moments.sort_by(f64::total_cmp);
    // The xy block's eigenvalues 2.1e-7 ± √(0.1² + 0.1²)e-7, and 1.8e-7.
    let r = 0.02f64.sqrt() * 1e-7;
    for (got, want) in moments.iter().zip([1.8e-7, 2.1e-7 - r, 2.1e-7 + r]) {
        assert!(rel(*got, want) < 1e-12, "{got} {want}");
    }
    assert!(!m.aligned());
    // No solid has moments that break the triangle inequality.
    s.features.inertia = Some([1e-7, 1e-7, 3e-7, 0.0, 0.0, 0.0]);
    assert!(MassProps::of(&s)
        .unwrap_err()
        .to_string()
        .contains("no solid has this inertia"));
}

#[test]
fn bad_dice_are_refused_by_field() {
    let half = Vector3::repeat(0.008);
    let field = |f: Features| match f.validate(&half, Mode::ThreeD) {
        Err(Error::Field { field, .. }) => field.name(),
        other => panic!("{other:?}"),
    };
    let pips = |d: f64, h: f64| {
        Some(Pips {
            diameter: d,
            depth: h,
            shape: PipShape::Cap,
            fill_density: 0.0,
            spacing: 0.25,
        })
    };
    assert_eq!(
        field(Features {
            edge_radius: 0.008,
            ..Default::default()
        }),
        "edge_radius"
    );
    assert_eq!(
        field(Features {
            edge_radius: -1e-3,
            ..Default::default()
        }),
        "edge_radius"
    );
    assert_eq!(
        field(Features {
            com: Some([0.0, 0.0, 0.009]),
            ..Default::default()
        }),
        "com"
    );
    assert_eq!(
        field(Features {
            com: Some([0.0, f64::NAN, 0.0]),
            ..Default::default()
        }),
        "com"
    );
    // Inside the sharp box's corner but outside the rounded one.
    assert_eq!(
        field(Features {
            com: Some([0.0079, 0.0079, 0.0079]),
            edge_radius: 0.002,
            ..Default::default()
        }),
        "com"
    );
    assert_eq!(
        field(Features {
            pips: pips(0.003, 0.002),
            ..Default::default()
        }),
        "pips.depth"
    );
    // 5 mm pips 4 mm apart overlap; 7 mm pips at 4 mm from the centre cross the edge.
    assert_eq!(
        field(Features {
            pips: pips(0.0045, 0.001),
            ..Default::default()
        }),
        "pips.diameter"
    );
    assert_eq!(
        field(Features {
            pips: pips(-1.0, 0.001),
            ..Default::default()
        }),
        "pips.diameter"
    );
    assert!(Features {
        pips: pips(0.003, 0.001),
        edge_radius: 0.001,
        ..Default::default()
    }
    .validate(&half, Mode::ThreeD)
    .is_ok());
    assert!(Features {
        com: Some([0.0, 0.0, 0.001]),
        ..Default::default()
    }
    .validate(&half, Mode::TwoD)
    .is_err());
}
