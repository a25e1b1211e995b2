//! Reading a die's mesh from an OBJ or STL (ASCII or binary) file already in memory: the caller
//! reads the bytes (through its own capped reader); this module never touches the file system.
//!
//! Parser crates, and why:
//! * `tobj` 4.0.5, with `default-features = false, features = ["use_f64"]`: the common Wavefront
//!   OBJ loader (after tinyobjloader); without default features it has no dependency at all, and
//!   `use_f64` keeps the coordinates in double precision. It handles the `v/vt/vn` index forms,
//!   relative (negative) indices, `w` coordinates, objects and groups. We ask it for the polygons
//!   as written (no triangulation: its fan is wrong for a non-convex face) and triangulate them
//!   by ear clipping here.
//! * `stl_io` 0.11: reads ASCII and binary STL; no dependency. It tells the two apart by a
//!   leading "solid ", which some CAD programs also write into a binary file's header, so the
//!   format is decided here (a binary file's size is exactly 84 + 50 × its triangle count).
//!
//! Neither uses nalgebra (they return plain `f32`/`f64` arrays), so no second nalgebra enters
//! the build. Vertices with exactly equal coordinates are welded ([`Mesh::welded`]): an STL
//! lists every triangle's corners separately, and OBJ exporters often split vertices at seams.
//!
//! Errors are one line, starting with the file's name, saying what is wrong and where (a line
//! of an OBJ file, a facet of an STL file, or the mesh's edge or triangle from [`Mesh::check`]).

use super::polytope::Mesh;
use nalgebra::Vector3;
use std::borrow::Cow;
use std::io::Cursor;

/// The file formats read here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (text).
    Obj,
    /// STL in its ASCII form ("solid … facet normal … vertex …").
    StlAscii,
    /// STL in its binary form (80-byte header, triangle count, 50 bytes per triangle).
    StlBinary,
}

/// Reads a mesh from an OBJ or STL file's bytes and checks that it bounds a solid
/// ([`Mesh::check`]: closed, consistently oriented, outward). `name_for_messages` (the file's
/// name or path) starts every error message, and its extension (`.obj`, `.stl`, any case)
/// chooses the format; without either extension the content decides ([`detect_format`]).
pub fn read_mesh(bytes: &[u8], name_for_messages: &str) -> Result<Mesh, String> {
    let mesh = parse_mesh(bytes, name_for_messages)?;
    mesh.check()
        .map_err(|e| one_line(&format!("{name_for_messages}: {e}")))?;
    let bodies = bodies(&mesh);
    if bodies > 1 {
        return Err(format!(
            "{name_for_messages}: the mesh is {bodies} separate bodies (each encloses a volume of \
             its own); a die is one body"
        ));
    }
    Ok(mesh)
}

/// The separate bodies of a closed mesh: its connected pieces that enclose a volume of their
/// own (outward, positive). A piece turned inward is a cavity inside one of them, not a body.
pub fn bodies(mesh: &Mesh) -> usize {
    let mut parent: Vec<usize> = (0..mesh.vertices.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for t in &mesh.triangles {
        for k in 1..3 {
            let (a, b) = (root(&mut parent, t[0]), root(&mut parent, t[k]));
            parent[a] = b;
        }
    }
    let mut volume: std::collections::HashMap<usize, f64> = Default::default();
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i]);
        *volume.entry(root(&mut parent, t[0])).or_default() += a.dot(&b.cross(&c)) / 6.0;
    }
    volume.values().filter(|v| **v > 0.0).count()
}

/// As [`read_mesh`], without the final check: the triangles as read (polygons triangulated,
/// equal vertices welded), e.g. to take the convex hull of a mesh that is not closed.
pub fn parse_mesh(bytes: &[u8], name_for_messages: &str) -> Result<Mesh, String> {
    let name = name_for_messages;
    let corners = match detect_format(bytes, name)? {
        Format::Obj => read_obj(bytes, name),
        Format::StlAscii => read_stl_ascii(bytes, name),
        Format::StlBinary => read_stl_binary(bytes, name),
    }
    .map_err(|e| one_line(&e))?;
    Ok(Mesh::welded(&corners))
}

/// The format of a file: by the name's extension (`.obj`: OBJ; `.stl`: binary if the size is
/// exactly 84 + 50 × the triangle count in its header, else ASCII if it starts with "solid"),
/// or, for another name, by the content alone (binary STL by size, ASCII STL by "solid", OBJ by
/// `v` and `f` lines).
pub fn detect_format(bytes: &[u8], name_for_messages: &str) -> Result<Format, String> {
    let name = name_for_messages;
    if bytes.is_empty() {
        return Err(format!("{name}: the file is empty"));
    }
    let extension = std::path::Path::new(name)
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let binary_size = (bytes.len() >= 84).then(|| {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]);
        84 + 50 * count as u64
    });
    let is_binary = binary_size == Some(bytes.len() as u64);
    let is_ascii = starts_with_solid(bytes);
    match extension.as_deref() {
        Some("obj") => Ok(Format::Obj),
        Some("stl") if is_binary => Ok(Format::StlBinary),
        Some("stl") if is_ascii => Ok(Format::StlAscii),
        Some("stl") => Err(match binary_size {
            Some(size) => format!(
                "{name}: not an STL file: it does not start with \"solid\" (ASCII), and as binary \
                 STL its header announces {} triangles ({size} bytes) but it has {} bytes",
                (size - 84) / 50,
                bytes.len()
            ),
            None => format!(
                "{name}: not an STL file: it does not start with \"solid\" (ASCII) and has {} \
                 bytes, fewer than the 84 of a binary STL header",
                bytes.len()
            ),
        }),
        _ if is_binary => Ok(Format::StlBinary),
        _ if is_ascii => Ok(Format::StlAscii),
        _ if looks_like_obj(bytes) => Ok(Format::Obj),
        _ => Err(format!(
            "{name}: not a mesh file: expected OBJ (.obj) or STL (.stl), and the content is \
             neither"
        )),
    }
}

fn one_line(s: &str) -> String {
    s.replace(['\r', '\n'], " ")
}

/// Whether the first word of the file is "solid" (an ASCII STL).
fn starts_with_solid(bytes: &[u8]) -> bool {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    let rest = &bytes[start..];
    rest.starts_with(b"solid") && rest.get(5).is_none_or(|b| b.is_ascii_whitespace())
}

/// UTF-8 text with at least one `v` line and one `f` line.
fn looks_like_obj(bytes: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return false;
    };
    let first_word = |l: &str| l.split_whitespace().next().map(str::to_owned);
    let words: Vec<Option<String>> = text.lines().map(first_word).collect();
    words.iter().any(|w| w.as_deref() == Some("v"))
        && words.iter().any(|w| w.as_deref() == Some("f"))
}

/// The triangles of an ASCII STL file.
fn read_stl_ascii(bytes: &[u8], name: &str) -> Result<Vec<[Vector3<f64>; 3]>, String> {
    // stl_io wants the first line to start with "solid " (with a space): a bare "solid" or one
    // after blank space is normalised. The rest is passed as is.
    let first_line_end = bytes
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len(), |i| i + 1);
    let mut text = b"solid mesh\n".to_vec();
    text.extend_from_slice(&bytes[first_line_end..]);
    read_stl_with(&text, name, "ASCII STL")
}

/// The triangles of a binary STL file (its size already checked against its count).
fn read_stl_binary(bytes: &[u8], name: &str) -> Result<Vec<[Vector3<f64>; 3]>, String> {
    // The 80-byte header is free text and ignored; if it starts with "solid", stl_io would take
    // the file for ASCII, so that word is blanked in a copy.
    let data: Cow<[u8]> = if bytes.starts_with(b"solid") {
        let mut copy = bytes.to_vec();
        copy[..5].fill(0);
        Cow::Owned(copy)
    } else {
        Cow::Borrowed(bytes)
    };
    read_stl_with(&data, name, "binary STL")
}

fn read_stl_with(bytes: &[u8], name: &str, kind: &str) -> Result<Vec<[Vector3<f64>; 3]>, String> {
    let mut cursor = Cursor::new(bytes);
    let reader = stl_io::create_stl_reader(&mut cursor)
        .map_err(|e| format!("{name}: not a valid {kind} file: {e}"))?;
    let mut triangles = Vec::new();
    for (i, t) in reader.enumerate() {
        let t = t.map_err(|e| format!("{name}: {kind}, facet {}: {e}", i + 1))?;
        triangles.push(
            t.vertices
                .map(|v| Vector3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]))),
        );
    }
    if triangles.is_empty() {
        return Err(format!("{name}: the {kind} file has no triangles"));
    }
    Ok(triangles)
}

/// The triangles of an OBJ file: every object and group, polygons triangulated.
fn read_obj(bytes: &[u8], name: &str) -> Result<Vec<[Vector3<f64>; 3]>, String> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        format!(
            "{name}: not an OBJ file: byte {} is not UTF-8 text",
            e.valid_up_to()
        )
    })?;
    // A byte-order mark (some Windows editors write one) and comments at the ends of lines
    // are not OBJ statements: tobj reads neither, so both are taken out, line for line.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let uncommented: String = text
        .split_inclusive('\n')
        .map(|l| match l.find('#') {
            Some(at) => format!("{}{}", &l[..at], if l.ends_with('\n') { "\n" } else { "" }),
            None => l.to_string(),
        })
        .collect();
    let text = uncommented.as_str();
    if let Some((i, line)) = text.lines().enumerate().find(|(_, l)| {
        let mut words = l.split_whitespace();
        words.next() == Some("f") && words.count() < 3
    }) {
        return Err(format!(
            "{name}: line {}: a face with {} vertices (`{}`): a face needs 3 or more",
            i + 1,
            line.split_whitespace().count() - 1,
            line.trim()
        ));
    }
    // tobj's defaults (derived: every option off) keep the faces as written, with no single
    // index and no triangulation; points and lines are skipped. `..Default::default()` also
    // fills the fields that tobj's optional features (`merging`, `reordering`) add, should
    // another crate of the build turn them on.
    let options = tobj::LoadOptions {
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    // Materials (mtllib) are not needed; they are not looked up.
    let (models, _materials) = tobj::load_obj_buf(&mut text.as_bytes(), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| match obj_error_line(text, e) {
        Some(line) => format!("{name}: line {line}: {e}"),
        None => format!("{name}: not a valid OBJ file: {e}"),
    })?;

    let mut triangles = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let position = |k: u32| {
            let k = 3 * k as usize;
            Vector3::new(
                mesh.positions[k],
                mesh.positions[k + 1],
                mesh.positions[k + 2],
            )
        };
        let arities: Vec<usize> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.iter().map(|&a| a as usize).collect()
        };
        let mut start = 0;
        for arity in arities {
            let face = &mesh.indices[start..start + arity];
            start += arity;
            if arity < 3 {
                continue;
            }
            let corners: Vec<Vector3<f64>> = face.iter().map(|&k| position(k)).collect();
            for [a, b, c] in triangulate(&corners) {
                triangles.push([corners[a], corners[b], corners[c]]);
            }
        }
    }
    if triangles.is_empty() {
        return Err(format!(
            "{name}: the OBJ file has no faces (no `f` line with 3 or more vertices)"
        ));
    }
    Ok(triangles)
}

/// The line (1-based) that most likely caused tobj's error: tobj reports what, not where. The
/// lines are checked with tobj's own rules for the kind of error reported.
fn obj_error_line(text: &str, err: tobj::LoadError) -> Option<usize> {
    use tobj::LoadError as E;
    let floats = |words: &[&str]| words.iter().all(|w| w.parse::<f64>().is_ok());
    let count = |key: &str| {
        text.lines()
            .filter(|l| l.split_whitespace().next() == Some(key))
            .count()
    };
    let totals = [count("v"), count("vt"), count("vn")];
    let mut seen = [0usize; 3];
    for (i, line) in text.lines().enumerate() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let Some((&key, args)) = words.split_first() else {
            continue;
        };
        let bad = match key {
            "v" => {
                seen[0] += 1;
                let ok = args.len() >= 3
                    && floats(&args[..3])
                    && match args.len() {
                        3 => true,
                        4 => args[3].parse::<f64>().is_ok_and(|w| w != 0.0),
                        6 => floats(&args[3..]),
                        _ => false,
                    };
                !ok && matches!(
                    err,
                    E::PositionParseError | E::ScalingByZeroError | E::ColorParseError
                )
            }
            "vt" => {
                seen[1] += 1;
                !(args.len() >= 2 && floats(&args[..2])) && err == E::TexcoordParseError
            }
            "vn" => {
                seen[2] += 1;
                !(args.len() >= 3 && floats(&args[..3])) && err == E::NormalParseError
            }
            "f" | "l" => args.iter().any(|token| {
                token.split('/').enumerate().any(|(slot, part)| {
                    if slot > 2 {
                        return err == E::FaceParseError;
                    }
                    if part.is_empty() {
                        return false;
                    }
                    match part.parse::<isize>() {
                        Err(_) => err == E::FaceParseError,
                        // Relative indices count back from the elements read so far; absolute
                        // ones may refer forward, to any element of the file.
                        Ok(x) => {
                            let out = if x < 0 {
                                x.unsigned_abs() > seen[slot]
                            } else {
                                x == 0 || x as usize > totals[slot]
                            };
                            out && matches!(
                                (slot, err),
                                (0, E::FaceVertexOutOfBounds)
                                    | (1, E::FaceTexCoordOutOfBounds)
                                    | (2, E::FaceNormalOutOfBounds)
                            )
                        }
                    }
                })
            }),
            _ => false,
        };
        if bad {
            return Some(i + 1);
        }
    }
    None
}

/// Triangles (indices into `corners`) covering a simple planar polygon, with its winding.
/// Ear clipping in the polygon's plane (the plane normal to its Newell normal, in which the
/// polygon runs counter-clockwise): a convex corner whose triangle holds no other corner is cut
/// off, until three corners remain. Correct for non-convex polygons; a degenerate one (no ear
/// found, e.g. all corners collinear) is finished as a fan, which [`Mesh::check`] then refuses.
fn triangulate(corners: &[Vector3<f64>]) -> Vec<[usize; 3]> {
    let n = corners.len();
    if n == 3 {
        return vec![[0, 1, 2]];
    }
    // Newell's normal: Σ p_i × p_{i+1}, twice the vector area, with the polygon's winding.
    let origin = corners[0];
    let normal: Vector3<f64> = (0..n)
        .map(|i| (corners[i] - origin).cross(&(corners[(i + 1) % n] - origin)))
        .sum();
    let mut remaining: Vec<usize> = (0..n).collect();
    let mut out = Vec::with_capacity(n - 2);
    if normal.norm() > 0.0 {
        let w = normal.normalize();
        let helper = if w.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let u = w.cross(&helper).normalize();
        let v = w.cross(&u);
        let p: Vec<(f64, f64)> = corners
            .iter()
            .map(|c| ((c - origin).dot(&u), (c - origin).dot(&v)))
            .collect();
        let cross = |a: (f64, f64), b: (f64, f64), c: (f64, f64)| {
            (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)
        };
        while remaining.len() > 3 {
            let m = remaining.len();
            let ear = (0..m).find(|&i| {
                let (ia, ib, ic) = (
                    remaining[(i + m - 1) % m],
                    remaining[i],
                    remaining[(i + 1) % m],
                );
                let (a, b, c) = (p[ia], p[ib], p[ic]);
                cross(a, b, c) > 0.0
                    && remaining.iter().all(|&j| {
                        j == ia
                            || j == ib
                            || j == ic
                            || cross(a, b, p[j]) < 0.0
                            || cross(b, c, p[j]) < 0.0
                            || cross(c, a, p[j]) < 0.0
                    })
            });
            let Some(i) = ear else { break };
            out.push([
                remaining[(i + m - 1) % m],
                remaining[i],
                remaining[(i + 1) % m],
            ]);
            remaining.remove(i);
        }
    }
    for k in 1..remaining.len() - 1 {
        out.push([remaining[0], remaining[k], remaining[k + 1]]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fmt::Write as _;

    /// The unit cube [−½, ½]³ as an OBJ with quad faces (counter-clockwise from outside).
    const CUBE_OBJ: &str = "# unit cube
o cube
v -0.5 -0.5 -0.5
v 0.5 -0.5 -0.5
v -0.5 0.5 -0.5
v 0.5 0.5 -0.5
v -0.5 -0.5 0.5
v 0.5 -0.5 0.5
v -0.5 0.5 0.5
v 0.5 0.5 0.5
vn 0 0 1
vt 0 0
f 1 3 4 2
f 5 6 8 7
f 1/1 2/1 6/1 5/1
f 3//1 7//1 8//1 4//1
f 1/1/1 5/1/1 7/1/1 3/1/1
f -7 -5 -1 -3
";

    /// The unit cube's triangles, each corner listed (as an STL does).
    fn cube_triangles() -> Vec<[[f32; 3]; 3]> {
        let corners: Vec<Vector3<f64>> = (0..8)
            .map(|i| {
                Vector3::new(
                    (i & 1) as f64 - 0.5,
                    ((i >> 1) & 1) as f64 - 0.5,
                    ((i >> 2) & 1) as f64 - 0.5,
                )
            })
            .collect();
        let cube = super::super::polytope::hull(&corners).unwrap();
        cube.triangles
            .iter()
            .map(|t| t.map(|k| cube.vertices[k].map(|c| c as f32).into()))
            .collect()
    }

    fn ascii_stl(first_line: &str, newline: &str) -> String {
        let mut s = format!("{first_line}{newline}");
        for t in cube_triangles() {
            let _ = write!(s, "  facet normal 0 0 0{newline}    outer loop{newline}");
            for v in t {
                let _ = write!(s, "      vertex {:e} {:e} {:e}{newline}", v[0], v[1], v[2]);
            }
            let _ = write!(s, "    endloop{newline}  endfacet{newline}");
        }
        s + "endsolid cube" + newline
    }

    /// A binary STL of the unit cube. A header starting with "solid …\n" makes stl_io's own
    /// test take the file for ASCII.
    fn binary_stl(header: &[u8]) -> Vec<u8> {
        let triangles = cube_triangles();
        let mut out = vec![0u8; 80];
        out[..header.len()].copy_from_slice(header);
        out.extend((triangles.len() as u32).to_le_bytes());
        for t in triangles {
            out.extend([0f32; 3].iter().flat_map(|c| c.to_le_bytes()));
            for v in t {
                out.extend(v.iter().flat_map(|c| c.to_le_bytes()));
            }
            out.extend([0u8; 2]);
        }
        out
    }

    fn assert_unit_cube(mesh: &Mesh, what: &str) {
        mesh.check().unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_eq!(mesh.vertices.len(), 8, "{what}");
        let mp = mesh.mass_properties();
        assert!(
            (mp.volume - 1.0).abs() < 1e-12,
            "{what}: volume {}",
            mp.volume
        );
        assert!(mp.centroid.norm() < 1e-12, "{what}");
    }

    #[test]
    fn cube_files_round_trip_through_a_temporary_directory() {
        let dir = std::env::temp_dir().join(format!("dicephys-mesh-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let with_stl_io = {
            let tris: Vec<stl_io::Triangle> = cube_triangles()
                .into_iter()
                .map(|t| stl_io::Triangle {
                    normal: stl_io::Normal::new([0.0; 3]),
                    vertices: t.map(stl_io::Vertex::new),
                })
                .collect();
            let mut out = Vec::new();
            stl_io::write_stl(&mut out, tris.iter()).unwrap();
            out
        };
        let files: Vec<(&str, Vec<u8>, Format)> = vec![
            ("cube.obj", CUBE_OBJ.as_bytes().to_vec(), Format::Obj),
            (
                "cube.stl",
                ascii_stl("solid cube", "\n").into_bytes(),
                Format::StlAscii,
            ),
            (
                "bare.STL",
                ascii_stl("  solid", "\r\n").into_bytes(),
                Format::StlAscii,
            ),
            ("cube_binary.stl", with_stl_io, Format::StlBinary),
            (
                "solid_header.stl",
                binary_stl(b"solid cube\nexported by CAD"),
                Format::StlBinary,
            ),
        ];
        for (file, bytes, format) in files {
            let path = dir.join(file);
            std::fs::write(&path, &bytes).unwrap();
            let read = std::fs::read(&path).unwrap();
            let name = path.display().to_string();
            assert_eq!(detect_format(&read, &name), Ok(format), "{file}");
            // By content alone, too.
            assert_eq!(
                detect_format(&read, "upload"),
                Ok(format),
                "{file} by content"
            );
            let mesh = read_mesh(&read, &name).unwrap_or_else(|e| panic!("{e}"));
            assert_unit_cube(&mesh, file);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn garbage_and_empty_files_are_refused_in_one_line() {
        let garbage: Vec<u8> = (0..300u32).map(|i| (i * 7919 % 251) as u8).collect();
        for name in ["die.stl", "die.obj", "die", "die.ply"] {
            for bytes in [&garbage[..], b"", b"hello world\n", &garbage[..40]] {
                let e = read_mesh(bytes, name).unwrap_err();
                assert!(e.starts_with(name) && !e.contains('\n'), "{e}");
                if bytes.is_empty() {
                    assert_eq!(e, format!("{name}: the file is empty"));
                }
            }
        }
        // A binary STL cut short, and an ASCII STL broken in its third facet.
        let cut = binary_stl(b"");
        let e = read_mesh(&cut[..cut.len() - 10], "cut.stl").unwrap_err();
        assert!(
            e.contains("announces 12 triangles (684 bytes) but it has 674"),
            "{e}"
        );
        let broken = ascii_stl("solid cube", "\n").replacen("endloop", "endlop", 3);
        let e = read_mesh(broken.as_bytes(), "broken.stl").unwrap_err();
        assert!(
            e.starts_with("broken.stl: ASCII STL, facet 1:") && !e.contains('\n'),
            "{e}"
        );
    }

    #[test]
    fn obj_errors_name_the_line() {
        let bad_face = CUBE_OBJ.replace("f 5 6 8 7", "f 5 6 x 7");
        let e = read_mesh(bad_face.as_bytes(), "bad.obj").unwrap_err();
        assert!(e.starts_with("bad.obj: line 14: face parse error"), "{e}");
        let bad_vertex = CUBE_OBJ.replace("v 0.5 0.5 0.5", "v 0.5 0.5");
        let e = read_mesh(bad_vertex.as_bytes(), "bad.obj").unwrap_err();
        assert!(
            e.starts_with("bad.obj: line 10: position parse error"),
            "{e}"
        );
        let out_of_range = CUBE_OBJ.replace("f 5 6 8 7", "f 5 6 9 7");
        let e = read_mesh(out_of_range.as_bytes(), "bad.obj").unwrap_err();
        assert!(
            e.starts_with("bad.obj: line 14: face vertex index out of bounds"),
            "{e}"
        );

        // An open mesh is read by parse_mesh but refused by read_mesh, naming the edge.
        let open = CUBE_OBJ.replace("f 1 3 4 2\n", "");
        assert!(parse_mesh(open.as_bytes(), "open.obj").is_ok());
        let e = read_mesh(open.as_bytes(), "open.obj").unwrap_err();
        assert!(
            e.starts_with("open.obj: edge ") && e.contains("not closed"),
            "{e}"
        );
        let e = read_mesh(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n", "points.obj").unwrap_err();
        assert!(e.contains("no faces"), "{e}");
    }

    #[test]
    fn obj_polygons_are_triangulated() {
        // An L-shaped prism whose caps are single hexagons, listed from a corner from which a
        // fan would leave the L: only ear clipping gets the volume (3) right.
        let l = [
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
            (0.0, 0.0),
        ];
        let mut obj = String::from("o L\n");
        for z in [0.0, 1.0] {
            for (x, y) in l {
                let _ = writeln!(obj, "v {x} {y} {z}");
            }
        }
        obj += "f 6 5 4 3 2 1\nf 7 8 9 10 11 12\n";
        for k in 0..6 {
            let k1 = (k + 1) % 6;
            let _ = writeln!(obj, "f {} {} {} {}", k + 1, k1 + 1, k1 + 7, k + 7);
        }
        let mesh = read_mesh(obj.as_bytes(), "l.obj").unwrap();
        assert_eq!(mesh.triangles.len(), 2 * 4 + 6 * 2);
        // A fan would have the same signed area; what tells is that every cap triangle faces
        // out (+z on the top, −z on the bottom).
        for &[a, b, c] in &mesh.triangles {
            let v = &mesh.vertices;
            let z = [v[a].z, v[b].z, v[c].z];
            if z[0] == z[1] && z[1] == z[2] {
                let n = (v[b] - v[a]).cross(&(v[c] - v[a]));
                assert_eq!(n.z > 0.0, z[0] == 1.0, "cap triangle {a} {b} {c}: {n:?}");
            }
        }
        let mp = mesh.mass_properties();
        assert!((mp.volume - 3.0).abs() < 1e-12, "{}", mp.volume);
        assert!((mp.centroid - Vector3::new(5.0 / 6.0, 5.0 / 6.0, 0.5)).norm() < 1e-12);

        // A pentagonal prism (pentagon caps, quad sides), the caps in a second group.
        let mut obj = String::new();
        for z in [-1.0, 1.0] {
            for k in 0..5 {
                let a = 2.0 * std::f64::consts::PI * k as f64 / 5.0;
                let _ = writeln!(obj, "v {:?} {:?} {z}", a.cos(), a.sin());
            }
        }
        for k in 0..5 {
            let k1 = (k + 1) % 5;
            let _ = writeln!(obj, "f {} {} {} {}", k + 1, k1 + 1, k1 + 6, k + 6);
        }
        obj += "g caps\nf 5 4 3 2 1\nf 6 7 8 9 10\n";
        let mesh = read_mesh(obj.as_bytes(), "pentagon.obj").unwrap();
        let area = 2.5 * (2.0 * std::f64::consts::PI / 5.0).sin();
        assert!((mesh.mass_properties().volume - 2.0 * area).abs() < 1e-12);

        // Triangulation keeps the winding and covers the polygon.
        let square: Vec<Vector3<f64>> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .iter()
            .map(|&(x, y)| Vector3::new(x, y, 3.0))
            .collect();
        let tris = triangulate(&square);
        assert_eq!(tris.len(), 2);
        for [a, b, c] in tris {
            let n = (square[b] - square[a]).cross(&(square[c] - square[a]));
            assert!((n.z - 1.0).abs() < 1e-15, "{n:?}");
        }
    }

    #[test]
    fn two_bodies_are_refused_and_a_cavity_is_not_a_body() {
        // A second cube, `scale` times the first and moved by `dx`, its faces reversed if
        // `inward` (a cavity's surface faces into the hollow).
        let with = |scale: f64, dx: f64, inward: bool| {
            let mut t = CUBE_OBJ.to_string();
            for line in CUBE_OBJ.lines().filter(|l| l.starts_with("v ")) {
                let v: Vec<f64> = line[2..].split(' ').map(|x| x.parse().unwrap()).collect();
                let _ = writeln!(
                    t,
                    "v {} {} {}",
                    scale * v[0] + dx,
                    scale * v[1],
                    scale * v[2]
                );
            }
            for f in [
                "1 3 4 2", "5 6 8 7", "1 2 6 5", "3 7 8 4", "1 5 7 3", "2 4 8 6",
            ] {
                let mut k: Vec<usize> = f
                    .split(' ')
                    .map(|i| i.parse::<usize>().unwrap() + 8)
                    .collect();
                if inward {
                    k.reverse();
                }
                let k: Vec<String> = k.iter().map(usize::to_string).collect();
                let _ = writeln!(t, "f {}", k.join(" "));
            }
            t
        };
        let e = read_mesh(with(1.0, 3.0, false).as_bytes(), "twin.obj").unwrap_err();
        assert!(e.contains("twin.obj: the mesh is 2 separate bodies"), "{e}");
        let hollow = read_mesh(with(0.5, 0.0, true).as_bytes(), "hollow.obj").unwrap();
        assert_eq!(bodies(&hollow), 1);
        assert!((hollow.mass_properties().volume - 0.875).abs() < 1e-12);
        // A byte-order mark, comments after statements, and a face of two vertices.
        let marked = format!("\u{feff}{CUBE_OBJ}");
        assert!(read_mesh(marked.as_bytes(), "bom.obj").is_ok());
        let commented: String = CUBE_OBJ.lines().map(|l| format!("{l}  # note\n")).collect();
        assert!(read_mesh(commented.as_bytes(), "c.obj").is_ok());
        let e = read_mesh(format!("{CUBE_OBJ}f 1 2\n").as_bytes(), "two.obj").unwrap_err();
        assert!(
            e.contains("two.obj: line 19: a face with 2 vertices"),
            "{e}"
        );
    }
}
