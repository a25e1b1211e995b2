//! The polytope's tests: mesh algebra against closed forms and parry, hulls, facets, the named
//! dice.

use super::catalogue::*;
use super::hull::*;
use super::mesh::*;
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// Relative closeness |a − b| ≤ tol · max(|a|, |b|, floor).
fn close(a: f64, b: f64, tol: f64, floor: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(floor)
}

fn assert_matrix_close(a: &Matrix3<f64>, b: &Matrix3<f64>, tol: f64, what: &str) {
    let scale = a.abs().max().max(b.abs().max());
    for i in 0..3 {
        for j in 0..3 {
            assert!(
                (a[(i, j)] - b[(i, j)]).abs() <= tol * scale,
                "{what}: entry ({i},{j}) is {} but should be {}\n{a}\n{b}",
                a[(i, j)],
                b[(i, j)]
            );
        }
    }
}

/// The box [x0, x0+a] × [y0, y0+b] × [z0, z0+c]; corner i = x + 2y + 4z (bits).
fn box_mesh(origin: Vector3<f64>, a: f64, b: f64, c: f64) -> Mesh {
    let vertices = (0..8)
        .map(|i| {
            origin
                + Vector3::new(
                    if i & 1 != 0 { a } else { 0.0 },
                    if i & 2 != 0 { b } else { 0.0 },
                    if i & 4 != 0 { c } else { 0.0 },
                )
        })
        .collect();
    let triangles = vec![
        [0, 2, 3],
        [0, 3, 1], // z = 0
        [4, 5, 7],
        [4, 7, 6], // z = c
        [0, 1, 5],
        [0, 5, 4], // y = 0
        [2, 6, 7],
        [2, 7, 3], // y = b
        [0, 4, 6],
        [0, 6, 2], // x = 0
        [1, 3, 7],
        [1, 7, 5], // x = a
    ];
    Mesh {
        vertices,
        triangles,
    }
}

/// Inertia of a box a×b×c about its centre, unit density.
fn box_inertia(a: f64, b: f64, c: f64) -> Matrix3<f64> {
    let m = a * b * c;
    Matrix3::from_diagonal(&Vector3::new(
        m * (b * b + c * c) / 12.0,
        m * (a * a + c * c) / 12.0,
        m * (a * a + b * b) / 12.0,
    ))
}

/// Parallel-axis theorem: inertia about a point at −d from the centroid.
fn shifted(inertia: &Matrix3<f64>, mass: f64, d: &Vector3<f64>) -> Matrix3<f64> {
    inertia + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * mass
}

#[test]
fn unit_cube_and_box_mass_properties() {
    let cube = box_mesh(Vector3::zeros(), 1.0, 1.0, 1.0);
    cube.check().unwrap();
    let mp = cube.mass_properties();
    assert!(close(mp.volume, 1.0, 1e-12, 0.0), "{}", mp.volume);
    assert!((mp.centroid - Vector3::repeat(0.5)).norm() < 1e-12);
    assert_matrix_close(
        &mp.inertia,
        &(Matrix3::identity() / 6.0),
        1e-12,
        "unit cube",
    );

    let (a, b, c) = (2.0, 3.0, 5.0);
    let origin = Vector3::new(-1.0, 4.0, 7.0);
    let bx = box_mesh(origin, a, b, c);
    bx.check().unwrap();
    let mp = bx.mass_properties();
    assert!(close(mp.volume, 30.0, 1e-12, 0.0), "{}", mp.volume);
    let centre = origin + Vector3::new(a, b, c) / 2.0;
    assert!((mp.centroid - centre).norm() < 1e-12 * centre.norm());
    assert_matrix_close(&mp.inertia, &box_inertia(a, b, c), 1e-12, "box");
}

#[test]
fn regular_tetrahedron_mass_properties() {
    // Alternate cube corners (edge 2√2), moved off the origin.
    let offset = Vector3::new(1.0, -2.0, 3.0);
    let points: Vec<Vector3<f64>> = [
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ]
    .iter()
    .map(|p| Vector3::from(*p) + offset)
    .collect();
    let mesh = hull(&points).unwrap();
    let mp = mesh.mass_properties();
    let a = 2.0 * 2f64.sqrt();
    let volume = a.powi(3) / (6.0 * 2f64.sqrt());
    assert!(
        close(mp.volume, volume, 1e-12, 0.0),
        "{} vs {volume}",
        mp.volume
    );
    assert!((mp.centroid - offset).norm() < 1e-12 * offset.norm());
    // A regular tetrahedron's inertia is isotropic: m a²/20 about every centroidal axis.
    let expected = Matrix3::identity() * (volume * a * a / 20.0);
    assert_matrix_close(&mp.inertia, &expected, 1e-12, "regular tetrahedron");
}

#[test]
fn regular_octahedron_mass_properties() {
    let r = 1.5;
    let points: Vec<Vector3<f64>> = (0..3)
        .flat_map(|i| [r, -r].map(|s| Vector3::ith(i, s)))
        .collect();
    let mesh = hull(&points).unwrap();
    let mp = mesh.mass_properties();
    let volume = 4.0 / 3.0 * r.powi(3);
    assert!(
        close(mp.volume, volume, 1e-12, 0.0),
        "{} vs {volume}",
        mp.volume
    );
    assert!(mp.centroid.norm() < 1e-12 * r);
    // m a²/10 with edge a = r√2, i.e. m r²/5 about every centroidal axis.
    let moment = volume * r * r / 5.0;
    for i in 0..3 {
        assert!(close(mp.inertia[(i, i)], moment, 1e-12, 0.0));
        for j in 0..3 {
            if i != j {
                assert!(mp.inertia[(i, j)].abs() <= 1e-12 * moment, "{}", mp.inertia);
            }
        }
    }
}

/// The L-shaped prism: [0,2]×[0,1] ∪ [0,1]×[1,2] in xy, z in [0, 1].
fn l_prism() -> Mesh {
    let polygon = [
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
        (0.0, 2.0),
    ];
    let cap = [[0, 1, 2], [0, 2, 3], [0, 3, 5], [3, 4, 5]];
    extrude(&polygon, &cap, 0.0, 1.0)
}

#[test]
fn non_convex_l_prism_by_parallel_axes() {
    let mesh = l_prism();
    mesh.check().unwrap();
    let mp = mesh.mass_properties();
    // Box A [0,2]×[0,1]×[0,1] (mass 2), box B [0,1]×[1,2]×[0,1] (mass 1).
    let (ca, cb) = (Vector3::new(1.0, 0.5, 0.5), Vector3::new(0.5, 1.5, 0.5));
    let centroid = (ca * 2.0 + cb) / 3.0;
    assert!(close(mp.volume, 3.0, 1e-12, 0.0));
    assert!((mp.centroid - centroid).norm() < 1e-12);
    let expected = shifted(&box_inertia(2.0, 1.0, 1.0), 2.0, &(ca - centroid))
        + shifted(&box_inertia(1.0, 1.0, 1.0), 1.0, &(cb - centroid));
    assert!(
        expected[(0, 1)].abs() > 0.1,
        "the L has a product of inertia"
    );
    assert_matrix_close(&mp.inertia, &expected, 1e-12, "L prism");
}

#[test]
fn cylinder_closed_form_and_polygon_prism_convergence() {
    let cyl = Cylinder {
        diameter: 2.0,
        height: 2.0,
    };
    cyl.check().unwrap();
    let mp = cyl.mass_properties();
    assert!(close(mp.volume, 2.0 * PI, 1e-15, 0.0));
    let expected = Matrix3::from_diagonal(&Vector3::new(7.0 * PI / 6.0, 7.0 * PI / 6.0, PI));
    assert_matrix_close(&mp.inertia, &expected, 1e-15, "cylinder");
    assert!(Cylinder {
        diameter: 0.0,
        height: 1.0
    }
    .check()
    .is_err());

    // A 2000-gon prism inscribed in the coin: area (N/2) r² sin(2π/N), relative error
    // ≈ (2π/N)²/6 ≈ 1.6e-6 in volume, ≈ 2× that in the moments about z.
    let coin = Cylinder {
        diameter: 25.0,
        height: 2.0,
    };
    let n = 2000;
    let prism = prism_mesh(n, coin.diameter, coin.height);
    prism.check().unwrap();
    let (p, c) = (prism.mass_properties(), coin.mass_properties());
    let err = (2.0 * PI / n as f64).powi(2);
    let polygon_area = n as f64 / 2.0 * 12.5f64.powi(2) * (2.0 * PI / n as f64).sin();
    assert!(close(p.volume, polygon_area * 2.0, 1e-12, 0.0));
    assert!(close(p.volume, c.volume, err / 5.0, 0.0));
    assert!(
        !close(p.volume, c.volume, err / 10.0, 0.0),
        "the error is the polygon's"
    );
    assert!(p.centroid.norm() < 1e-12 * coin.diameter);
    assert_matrix_close(
        &p.inertia,
        &c.inertia,
        err / 2.0,
        "2000-gon prism vs cylinder",
    );
}

/// parry's mass properties of a mesh: `from_trimesh`, and the inertia tensor it diagonalises,
/// summed from parry's public per-tetrahedron tensor exactly as `from_trimesh` does (about
/// parry's centre of mass).
fn parry_mass_properties(
    mesh: &Mesh,
) -> (parry3d_f64::mass_properties::MassProperties, Matrix3<f64>) {
    use parry3d_f64::mass_properties::details::{
        tetrahedron_unit_inertia_tensor_wrt_point, trimesh_signed_volume_and_center_of_mass,
    };
    use parry3d_f64::math::Vector;
    let v: Vec<Vector> = mesh
        .vertices
        .iter()
        .map(|p| Vector::new(p.x, p.y, p.z))
        .collect();
    let t: Vec<[u32; 3]> = mesh.triangles.iter().map(|t| t.map(|k| k as u32)).collect();
    let props = parry3d_f64::mass_properties::MassProperties::from_trimesh(1.0, &v, &t);
    let (_, com) = trimesh_signed_volume_and_center_of_mass(&v, &t);
    let mut tensor = Matrix3::zeros();
    for tri in &t {
        let [p2, p3, p4] = tri.map(|k| v[k as usize]);
        let volume = parry3d_f64::shape::Tetrahedron::new(com, p2, p3, p4).signed_volume();
        let part = tetrahedron_unit_inertia_tensor_wrt_point(com, com, p2, p3, p4);
        tensor += Matrix3::from_fn(|r, c| part.col(c)[r]) * volume;
    }
    (props, tensor)
}

#[test]
fn mass_properties_agree_with_parry() {
    for (name, mesh) in [
        ("d20", named("d20", None).unwrap().mesh),
        ("d10", named("d10", None).unwrap().mesh),
        (
            "L prism",
            l_prism().translated(&Vector3::new(3.0, -1.0, 2.0)),
        ),
    ] {
        let ours = mesh.mass_properties();
        let (theirs, tensor) = parry_mass_properties(&mesh);
        assert!(
            close(ours.volume, theirs.mass(), 1e-9, 0.0),
            "{name}: volume {} vs parry {}",
            ours.volume,
            theirs.mass()
        );
        let com = Vector3::new(theirs.local_com.x, theirs.local_com.y, theirs.local_com.z);
        let size = mesh.bounding_diagonal();
        assert!(
            (ours.centroid - com).norm() <= 1e-9 * size,
            "{name}: centroid {} vs parry {com}",
            ours.centroid
        );
        // The whole tensor, products of inertia included, in the mesh's axes.
        assert_matrix_close(&ours.inertia, &tensor, 1e-9, name);
        // Principal moments: against the eigenvalues of parry's tensor to 1e-9, and against
        // `from_trimesh`'s own principal moments to 1e-7 only: parry diagonalises by the
        // closed-form (trigonometric) roots of the 3×3 characteristic cubic, which lose half
        // the digits (√ε ≈ 1e-8) when two moments are equal, as the d10's are (about x and
        // y). Their sum (the trace) it keeps exactly.
        let (moments, _) = ours.principal();
        let (of_tensor, _) = VolumeIntegrals {
            inertia: tensor,
            ..ours
        }
        .principal();
        let pi = theirs.principal_inertia();
        let mut from_trimesh = [pi.x, pi.y, pi.z];
        from_trimesh.sort_by(f64::total_cmp);
        for i in 0..3 {
            assert!(
                close(moments[i], of_tensor[i], 1e-9, 0.0),
                "{name}: principal moment {i}: {} vs parry's tensor {}",
                moments[i],
                of_tensor[i]
            );
            assert!(
                close(moments[i], from_trimesh[i], 1e-7, 0.0),
                "{name}: principal moment {i}: {} vs parry {}",
                moments[i],
                from_trimesh[i]
            );
        }
        let trace: f64 = from_trimesh.iter().sum();
        assert!(close(moments.sum(), trace, 1e-9, 0.0), "{name}: trace");
    }
}

#[test]
fn check_refuses_open_flipped_inside_out_and_bad_data() {
    let cube = box_mesh(Vector3::zeros(), 1.0, 1.0, 1.0);
    assert_eq!(cube.check(), Ok(()));

    let mut open = cube.clone();
    open.triangles.remove(5); // [0, 5, 4]
    let e = open.check().unwrap_err();
    assert!(e.contains("not closed") && e.starts_with("edge "), "{e}");
    assert!(
        e.starts_with("edge 4–5 belongs to 1 triangle (triangle 2)"),
        "{e}"
    );

    let mut flipped = cube.clone();
    flipped.triangles[7].swap(1, 2);
    let e = flipped.check().unwrap_err();
    assert!(
        e.contains("not consistently oriented") && e.contains('7'),
        "{e}"
    );

    let e = cube.scaled(-1.0).scaled(-1.0).check();
    assert_eq!(e, Ok(()), "mirroring twice keeps the orientation");
    let mut inside_out = cube.clone();
    for t in &mut inside_out.triangles {
        t.swap(1, 2);
    }
    let e = inside_out.check().unwrap_err();
    assert!(e.contains("inside out"), "{e}");

    let mut bad = cube.clone();
    bad.triangles[3] = [4, 7, 8];
    assert!(bad
        .check()
        .unwrap_err()
        .contains("triangle 3 refers to vertex 8"));
    let mut bad = cube.clone();
    bad.vertices[2].y = f64::NAN;
    assert!(bad
        .check()
        .unwrap_err()
        .contains("vertex 2 has a non-finite"));
    let mut bad = cube.clone();
    bad.vertices[3] = (bad.vertices[0] + bad.vertices[1]) / 2.0;
    assert!(bad.check().unwrap_err().contains("zero area"));
    let mut bad = cube.clone();
    bad.triangles.extend([[0, 1, 2], [0, 2, 1]]);
    assert!(bad.check().unwrap_err().contains("not a closed manifold"));

    for e in [
        open.check(),
        flipped.check(),
        inside_out.check(),
        bad.check(),
    ] {
        assert!(!e.unwrap_err().contains('\n'));
    }
}

#[test]
fn welded_soup_and_scaling() {
    let cube = box_mesh(Vector3::new(-0.5, -0.5, -0.5), 1.0, 1.0, 1.0);
    let soup: Vec<[Vector3<f64>; 3]> = cube
        .triangles
        .iter()
        .map(|t| t.map(|k| cube.vertices[k]))
        .collect();
    let welded = Mesh::welded(&soup);
    assert_eq!(welded.vertices.len(), 8);
    welded.check().unwrap();
    // −0 and +0 weld.
    let w = Mesh::welded(&[[
        Vector3::new(0.0, 1.0, 2.0),
        Vector3::new(-0.0, 1.0, 2.0),
        Vector3::x(),
    ]]);
    assert_eq!(w.vertices.len(), 2);

    let mp = welded.mass_properties();
    for s in [2.0, -3.0] {
        let m = welded.scaled(s);
        m.check().unwrap();
        let sp = m.mass_properties();
        assert!(close(sp.volume, mp.volume * s.abs().powi(3), 1e-12, 0.0));
        assert_matrix_close(
            &sp.inertia,
            &(mp.inertia * s.abs().powi(5)),
            1e-12,
            "scaled",
        );
    }
}

#[test]
fn hull_of_a_point_cloud_and_degenerate_points() {
    let mut points: Vec<Vector3<f64>> = signs3()
        .map(|[x, y, z]| Vector3::new(x, y, z) * 0.5)
        .collect();
    // Interior points, deterministic.
    for i in 0..50 {
        let t = i as f64;
        points.push(Vector3::new((t * 0.37).sin(), (t * 0.71).cos(), (t * 1.3).sin()) * 0.49);
    }
    let h = hull(&points).unwrap();
    assert_eq!(h.vertices.len(), 8);
    assert!(close(h.mass_properties().volume, 1.0, 1e-12, 0.0));
    let flat: Vec<Vector3<f64>> = (0..6)
        .map(|i| Vector3::new(i as f64, (i * i) as f64, 0.0))
        .collect();
    let e = hull(&flat).unwrap_err();
    assert!(!e.contains('\n'), "{e}");
    assert!(hull(&points[..3])
        .unwrap_err()
        .contains("at least 4 points"));
    // Degenerate inputs are refused, not a panic.
    let same = vec![Vector3::new(1.0, 2.0, 3.0); 6];
    let line: Vec<Vector3<f64>> = (0..6).map(|i| Vector3::repeat(i as f64)).collect();
    for points in [same, line] {
        let e = hull(&points).unwrap_err();
        assert!(!e.contains('\n'), "{e}");
    }
    let mut with_nan = points.clone();
    with_nan[5].z = f64::NAN;
    assert!(hull(&with_nan)
        .unwrap_err()
        .starts_with("point 5 has a non-finite"));
}

const DICE: [(&str, usize, usize, usize); 6] = [
    // name, faces, corners per face, vertices
    ("d4", 4, 3, 4),
    ("d6", 6, 4, 8),
    ("d8", 8, 3, 6),
    ("d10", 10, 4, 12),
    ("d12", 12, 5, 20),
    ("d20", 20, 3, 12),
];

#[test]
fn facets_of_the_named_dice() {
    let cube = hull(
        &signs3()
            .map(|[x, y, z]| Vector3::new(x, y, z))
            .collect::<Vec<_>>(),
    )
    .unwrap();
    assert_eq!(cube.triangles.len(), 12);
    let f = facets(&cube, COPLANAR_TOLERANCE);
    assert_eq!(f.len(), 6);
    assert!(f
        .iter()
        .all(|f| f.polygon.len() == 4 && close(f.area, 4.0, 1e-12, 0.0)));

    // A cube with a vertex added at the middle of the top edge 4–5: it is a corner of no
    // face, so both faces that hold it still have 4 corners.
    let mut split = box_mesh(Vector3::zeros(), 1.0, 1.0, 1.0);
    split.vertices.push(Vector3::new(0.5, 0.0, 1.0));
    let tri = |t: &[usize; 3]| split.triangles.iter().position(|u| u == t).unwrap();
    let (top, side) = (tri(&[4, 5, 7]), tri(&[0, 5, 4]));
    split.triangles[top] = [4, 8, 7];
    split.triangles[side] = [0, 5, 8];
    split.triangles.extend([[8, 5, 7], [0, 8, 4]]);
    split.check().unwrap();
    let f = facets(&split, COPLANAR_TOLERANCE);
    assert_eq!(f.len(), 6);
    for f in &f {
        assert_eq!(f.polygon.len(), 4, "{:?}", f.polygon);
        assert!(!f.polygon.contains(&Vector3::new(0.5, 0.0, 1.0)));
    }

    for (name, faces, corners, vertices) in DICE {
        let die = named(name, None).unwrap();
        die.mesh.check().unwrap();
        assert_eq!(die.mesh.vertices.len(), vertices, "{name}");
        let fs = facets(&die.mesh, COPLANAR_TOLERANCE);
        assert_eq!(fs.len(), faces, "{name}");
        let size = die.mesh.bounding_diagonal();
        let total_area: f64 = die
            .mesh
            .triangles
            .iter()
            .map(|&[a, b, c]| {
                let v = &die.mesh.vertices;
                (v[b] - v[a]).cross(&(v[c] - v[a])).norm() / 2.0
            })
            .sum();
        assert!(close(
            fs.iter().map(|f| f.area).sum(),
            total_area,
            1e-12,
            0.0
        ));
        for f in &fs {
            assert_eq!(f.polygon.len(), corners, "{name}");
            assert!((f.normal.norm() - 1.0).abs() < 1e-12, "{name}");
            assert!(
                close(f.area, fs[0].area, 1e-12, 0.0),
                "{name}: congruent faces"
            );
            // Corners on the plane, counter-clockwise seen from outside.
            let n = f.polygon.len();
            for i in 0..n {
                let (a, b, c) = (f.polygon[i], f.polygon[(i + 1) % n], f.polygon[(i + 2) % n]);
                assert!(
                    (f.normal.dot(&a) - f.offset).abs() < 1e-12 * size,
                    "{name}: planar"
                );
                assert!(
                    (b - a).cross(&(c - b)).dot(&f.normal) > 0.0,
                    "{name}: convex, ccw"
                );
            }
            for v in &die.mesh.vertices {
                assert!(
                    f.normal.dot(v) <= f.offset + 1e-12 * size,
                    "{name}: hull inside"
                );
            }
        }
    }
}

#[test]
fn d10_kites_are_planar() {
    let p = d10_points();
    let (top, bottom) = (p[10], p[11]);
    for j in 0..5 {
        // Top kite (T, v2j, v2j+1, v2j+2) and bottom kite (B, v2j+1, v2j+2, v2j+3).
        for (apex, k) in [(top, 2 * j), (bottom, 2 * j + 1)] {
            let (a, b, c) = (
                p[k % 10] - apex,
                p[(k + 1) % 10] - apex,
                p[(k + 2) % 10] - apex,
            );
            let triple = a.dot(&b.cross(&c));
            assert!(triple.abs() < 1e-14, "kite {k}: {triple}");
        }
    }
    // A slightly wrong ring height breaks each kite into two faces.
    let mut q = p.clone();
    for v in q.iter_mut().take(10) {
        v.z *= 1.01;
    }
    let fs = facets(&hull(&q).unwrap(), COPLANAR_TOLERANCE);
    assert_eq!(fs.len(), 20);
}

#[test]
fn sizes_and_centring_of_the_named_dice() {
    for (name, default, _) in DEFAULT_SIZES_MM {
        for size in [None, Some(1.0)] {
            let die = named(name, size).unwrap();
            let s = size.unwrap_or(default);
            let mp = die.mesh.mass_properties();
            assert!(mp.centroid.norm() < 1e-12 * s, "{name}: centred");
            if name == "d4" {
                let [a, b, _] = die.mesh.triangles[0];
                let edge = (die.mesh.vertices[a] - die.mesh.vertices[b]).norm();
                assert!(close(edge, s, 1e-12, 0.0), "{name}: edge {edge}");
                assert!(close(
                    mp.volume,
                    s.powi(3) / (6.0 * 2f64.sqrt()),
                    1e-12,
                    0.0
                ));
            } else {
                for f in facets(&die.mesh, COPLANAR_TOLERANCE) {
                    assert!(
                        close(2.0 * f.offset, s, 1e-12, 0.0),
                        "{name}: face distance"
                    );
                }
            }
        }
    }
    // The d10's proportions: apex to apex = √(1 + (1 + tan²(π/10))²) × face to face.
    let d10 = named("d10", Some(1.0)).unwrap();
    let height = d10
        .mesh
        .vertices
        .iter()
        .map(|v| v.z)
        .fold(f64::MIN, f64::max)
        * 2.0;
    let t2 = (PI / 10.0).tan().powi(2);
    assert!(
        close(height, (1.0 + (1.0 + t2).powi(2)).sqrt(), 1e-12, 0.0),
        "{height}"
    );
}

#[test]
fn labels_of_the_named_dice() {
    for (name, faces, _, _) in DICE {
        let die = named(name, None).unwrap();
        assert_eq!(die.labels.len(), faces, "{name}");
        let mut numbers: Vec<usize> = die.labels.iter().map(|l| l.1.parse().unwrap()).collect();
        numbers.sort_unstable();
        assert_eq!(
            numbers,
            (1..=faces).collect::<Vec<_>>(),
            "{name}: each label once"
        );
        let fs = facets(&die.mesh, COPLANAR_TOLERANCE);
        for (n, label) in &die.labels {
            assert!(
                fs.iter().any(|f| (f.normal - n).norm() < 1e-9),
                "{name}: label {label} is on a facet"
            );
            if name != "d4" {
                let (_, opposite) = die
                    .labels
                    .iter()
                    .find(|(m, _)| (m + n).norm() < 1e-9)
                    .expect("an opposite face");
                let sum: usize =
                    label.parse::<usize>().unwrap() + opposite.parse::<usize>().unwrap();
                assert_eq!(sum, faces + 1, "{name}: {label} + {opposite}");
            }
        }
        let expected = if name == "d4" { Reads::Down } else { Reads::Up };
        assert_eq!(die.reads, expected);
    }

    // The d6: 1 +z, 6 −z, 2 +x, 5 −x, 3 +y, 4 −y.
    let d6 = named("d6", None).unwrap();
    let want = [
        (Vector3::z(), "1"),
        (-Vector3::z(), "6"),
        (Vector3::x(), "2"),
        (-Vector3::x(), "5"),
        (Vector3::y(), "3"),
        (-Vector3::y(), "4"),
    ];
    for (n, label) in want {
        let got = d6
            .labels
            .iter()
            .find(|(m, _)| (m - n).norm() < 1e-12)
            .unwrap();
        assert_eq!(got.1, label, "d6 face {n:?}");
    }
    // Right-handed: 1, 2, 3 counter-clockwise seen from outside their common corner.
    let corner = Vector3::new(1.0, 1.0, 1.0);
    assert!(Vector3::z().cross(&Vector3::x()).dot(&corner) > 0.0);

    // The d10: odd labels meet at one apex, even at the other.
    let d10 = named("d10", None).unwrap();
    for (n, label) in &d10.labels {
        let odd = label.parse::<usize>().unwrap() % 2 == 1;
        assert_eq!(odd, n.z < 0.0, "d10 label {label} at {n:?}");
    }
}

#[test]
fn prism_dice() {
    let die = named("prism:6,16,30", None).unwrap();
    die.mesh.check().unwrap();
    let fs = facets(&die.mesh, COPLANAR_TOLERANCE);
    assert_eq!(fs.len(), 8);
    assert_eq!(die.labels.len(), 8);
    for (n, _) in &die.labels {
        assert!(fs.iter().any(|f| (f.normal - n).norm() < 1e-12));
    }
    assert_eq!(die.labels[0].1, "1");
    assert!((die.labels[0].0 - Vector3::x()).norm() < 1e-15);
    assert_eq!(die.labels[6].1, "top");
    assert_eq!(die.labels[7].1, "bottom");
    let mp = die.mesh.mass_properties();
    let hexagon = 3.0 * 3f64.sqrt() / 2.0 * 64.0;
    assert!(close(mp.volume, hexagon * 30.0, 1e-12, 0.0));
    assert!(mp.centroid.norm() < 1e-12);
    let square = named("PRISM:4, 2, 40", None).unwrap();
    assert!(close(
        square.mesh.mass_properties().volume,
        2.0 * 40.0,
        1e-12,
        0.0
    ));
    for bad in [
        "prism:1000000,16,30",
        "prism:2,16,30",
        "prism:6,16",
        "prism:6,-1,30",
        "prism:x,1,1",
        "prism:6,1,inf",
    ] {
        let e = named(bad, None).unwrap_err();
        assert!(e.contains("prism:N,D,L") && !e.contains('\n'), "{e}");
    }
    assert!(named("prism:6,16,30", Some(3.0))
        .unwrap_err()
        .contains("no size"));
}

#[test]
fn named_refuses_unknown_names_and_bad_sizes() {
    let e = named("d7", None).unwrap_err();
    assert!(e.contains("unknown die \"d7\""), "{e}");
    for s in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(named("d6", Some(s))
            .unwrap_err()
            .contains("positive length"));
    }
    assert!(named(" D20 ", None).is_ok());
}

#[test]
fn stability_of_faces() {
    for (name, _, _, _) in DICE {
        let die = named(name, None).unwrap();
        let com = die.mesh.mass_properties().centroid;
        for f in facets(&die.mesh, COPLANAR_TOLERANCE) {
            assert!(stable(&f, &com, 0.0), "{name}: every face stable");
            assert!(!stable(&f, &com, 100.0), "{name}: not by 100 mm");
        }
    }
    // An obtuse tetrahedron: its centroid (1, 1, 1/4) falls outside the base triangle.
    let tet = hull(&[
        Vector3::zeros(),
        Vector3::x(),
        Vector3::y(),
        Vector3::new(3.0, 3.0, 1.0),
    ])
    .unwrap();
    let com = tet.mass_properties().centroid;
    assert!((com - Vector3::new(1.0, 1.0, 0.25)).norm() < 1e-12);
    let fs = facets(&tet, COPLANAR_TOLERANCE);
    let base = fs
        .iter()
        .find(|f| (f.normal + Vector3::z()).norm() < 1e-12)
        .unwrap();
    assert!(!stable(base, &com, 0.0), "the base is not a resting face");
    assert!(fs.iter().any(|f| stable(f, &com, 0.0)), "some face is");

    // A long square prism: the sides are stable about the centroid but not about a point
    // beyond a cap; the margin is a length.
    let rod = named("prism:4,2,40", None).unwrap();
    let fs = facets(&rod.mesh, COPLANAR_TOLERANCE);
    let side = fs
        .iter()
        .find(|f| (f.normal - Vector3::x()).norm() < 1e-12)
        .unwrap();
    let half_width = 2f64.sqrt() / 2.0;
    assert!(stable(side, &Vector3::zeros(), 0.0));
    assert!(stable(side, &Vector3::zeros(), half_width * 0.99));
    assert!(!stable(side, &Vector3::zeros(), half_width * 1.01));
    assert!(stable(side, &Vector3::new(0.0, 0.0, 19.0), 0.0));
    assert!(!stable(side, &Vector3::new(0.0, 0.0, 21.0), 0.0));
}
