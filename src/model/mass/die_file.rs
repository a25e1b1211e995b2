//! Reading a die file (TOML, lengths in mm): the features it describes, and the die of any
//! shape it (or `--shape`) names.

use super::features::{Features, Insert, Pips, Shell};
use crate::error::{Error, Field, Result};
use crate::model::faces::Layout;
use crate::model::shape::{self, Shape};
use nalgebra::Vector3;
use serde::Deserialize;

/// A die file (TOML), every length in mm, every key optional:
///
/// ```toml
/// com = [0.0, 0.0, -2.0]   # the centre of mass from the geometric centre, body axes
/// edge_radius = 1.0        # edges and corners rounded
/// density = 1180.0         # kg/m³ (the solid's)
/// [pips]
/// diameter = 3.0
/// depth = 1.0
/// shape = "cap"            # or "cylinder"
/// fill_density = 1400.0    # paint, kg/m³ (0: empty)
/// spacing = 0.25           # off-centre pips' distance from the face's centre / its side
/// [shell]                  # a printed die: a solid wall and a sparse infill inside
/// wall = 1.0               # the wall's thickness
/// infill = 0.2             # the infill's volume fraction, 0 to 1
/// ```
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DieFile {
    /// mm.
    pub com: Option<[f64; 3]>,
    /// mm.
    pub edge_radius: Option<f64>,
    /// kg/m³.
    pub density: Option<f64>,
    /// Pips, in mm.
    pub pips: Option<Pips>,
    /// "right" or "left".
    pub layout: Option<Layout>,
    /// The number on each face: `{ "+x" = 2, "-x" = 5, … }`.
    pub faces: Option<std::collections::BTreeMap<String, u8>>,
    /// An insert, in mm and kg/m³.
    pub insert: Option<Insert>,
    /// The inertia about the centre of mass, g mm²: xx, yy, zz, xy, xz, yz.
    pub inertia: Option<[f64; 6]>,
    /// A printed die's wall (mm) and infill (a fraction).
    pub shell: Option<ShellDef>,
    /// A die of any shape: its mesh (OBJ or STL, in mm; a path from the die file's folder).
    pub mesh: Option<std::path::PathBuf>,
    /// The mesh's lengths times this (e.g. 25.4 for a mesh in inches).
    pub scale: Option<f64>,
    /// Which face's label the die shows: "up" (most dice) or "down" (a d4).
    pub reads: Option<crate::model::shape::Reads>,
    /// The mesh's facets' labels: `{ normal = [0, 0, 1], label = "6" }`, one per resting
    /// facet (matched by its outward normal); none: numbered 1…N.
    pub labels: Option<Vec<LabelDef>>,
}

/// A printed die's shell in a die file: `[shell]` with `wall` (mm) and `infill` (0 to 1).
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShellDef {
    /// The wall's thickness, mm.
    pub wall: f64,
    /// The infill's volume fraction.
    pub infill: f64,
}

/// A mesh's labels: each facet's outward normal (unit length) and what it shows.
pub type MeshLabels = Vec<(nalgebra::Vector3<f64>, String)>;

/// One facet's label in a die file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelDef {
    /// The facet's outward normal, body axes (any length).
    pub normal: [f64; 3],
    /// What it carries.
    pub label: String,
}

/// How the model is given a die's files (a die file, the mesh it names): the bytes of the
/// file at a path, at most so many. The model parses what it is given; reading, its cap and a
/// stop request while it blocks stay with the other file reading (`run::io::read_die_bytes`).
pub type ReadFile<'a> = &'a dyn Fn(&std::path::Path, u64) -> Result<Vec<u8>>;

/// The largest die file read (TOML): 1 MiB.
pub const MAX_DIE_FILE: u64 = 1 << 20;

/// True if `path` names a mesh by its extension (.obj, .stl).
pub fn is_mesh(path: &std::path::Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("obj") || e.eq_ignore_ascii_case("stl"))
}

impl DieFile {
    /// Reads and parses a die file, its bytes through `read` (`run::io::read_die_bytes`: a
    /// missing file, a directory, a pipe or a file over 1 MiB is refused naming `--die`, and a
    /// stop request is honoured while it blocks): a key it does not know, a value of the
    /// wrong kind, or a file that is not TOML is one line naming it. A mesh (.obj, .stl)
    /// describes no features: its die file is empty.
    pub fn read(path: &std::path::Path, read: ReadFile) -> Result<DieFile> {
        if is_mesh(path) {
            return Ok(DieFile::default());
        }
        let bytes = read(path, MAX_DIE_FILE)?;
        let text = String::from_utf8(bytes).map_err(|_| {
            Error::field(
                Field::Die,
                path.display(),
                "is not a text file (a die file is TOML; a mesh is .obj or .stl)",
            )
        })?;
        let file: DieFile = toml::from_str(&text).map_err(|e| {
            let line = e
                .span()
                .map(|s| format!(" (line {})", text[..s.start].matches('\n').count() + 1))
                .unwrap_or_default();
            Error::Invalid(format!(
                "die file {}{line}: {}",
                path.display(),
                e.message().trim()
            ))
        })?;
        // An empty file (`/dev/null`, a file not yet written) describes nothing: refused,
        // not rolled as the plain die.
        if toml::from_str::<toml::Table>(&text).is_ok_and(|t| t.is_empty()) {
            return Err(Error::field(
                Field::Die,
                path.display(),
                "the die file is empty: give the die's features (com, pips, …) or a mesh",
            ));
        }
        Ok(file)
    }

    /// A mesh's labels as the file gives them, checked, each normal of unit length: refused
    /// (the reason) where a label cannot be named or written ([`check_label`]), a normal is
    /// not a direction (NaN, infinite or zero), or two labels name the same facet.
    ///
    /// [`check_label`]: crate::model::shape::check_label
    pub fn mesh_labels(&self) -> std::result::Result<Option<MeshLabels>, String> {
        let Some(defs) = &self.labels else {
            return Ok(None);
        };
        let mut out: MeshLabels = Vec::new();
        for d in defs {
            crate::model::shape::check_label(&d.label)?;
            let n = nalgebra::Vector3::from(d.normal);
            let shown = d.normal.map(|x| x.to_string()).join(", ");
            if !n.iter().all(|x| x.is_finite()) || n.norm() == 0.0 || !n.norm().is_finite() {
                return Err(format!(
                    "label '{}': its normal [{shown}] is not a direction (give three finite \
                     numbers, not all zero)",
                    d.label
                ));
            }
            let n = n.normalize();
            if let Some((_, other)) = out.iter().find(|(m, _)| m.dot(&n) > 1.0 - 1e-6) {
                return Err(format!(
                    "labels '{other}' and '{}' have the same normal [{shown}]: a facet has one \
                     label",
                    d.label
                ));
            }
            out.push((n, d.label.clone()));
        }
        Ok(Some(out))
    }

    /// The features it describes, lengths in metres; a face map that is not a permutation of
    /// 1 to 6, or given beside `layout`, is refused.
    pub fn features(&self) -> Result<Features> {
        let layout = match (&self.faces, self.layout) {
            (Some(_), Some(_)) => {
                return Err(Error::field(
                    Field::Faces,
                    "",
                    "give either a layout or a face map, not both",
                ))
            }
            (Some(map), None) => Layout::from_map(map)?,
            (None, l) => l.unwrap_or_default(),
        };
        let mm = |c: [f64; 3]| c.map(|x| x / 1000.0);
        Ok(Features {
            com: self.com.map(mm),
            pips: self.pips.as_ref().map(|p| Pips {
                diameter: p.diameter / 1000.0,
                depth: p.depth / 1000.0,
                ..*p
            }),
            edge_radius: self.edge_radius.unwrap_or(0.0) / 1000.0,
            layout,
            insert: self.insert.map(|i| Insert {
                size: mm(i.size),
                centre: mm(i.centre),
                density: i.density,
            }),
            // g mm² = 10⁻³ kg × 10⁻⁶ m².
            inertia: self.inertia.map(|t| t.map(|x| x * 1e-9)),
            shell: self.shell.map(|s| Shell {
                wall: s.wall / 1000.0,
                infill: s.infill,
            }),
        })
    }
}

impl Features {
    /// A die as the command line and the Python package describe it: a die file's, if one is
    /// named (its bytes through `read`), with a centre of mass, pips' diameter and depth, an
    /// edge radius and a shell (its wall in mm, its infill a fraction) given laid over it
    /// ([`Features::with_mm`]). Returns the features and the density given (`density`, else
    /// the file's). The numbering asked is laid over
    /// by the caller (`run::request::DieRequest::resolve`).
    pub fn described(
        file: Option<&std::path::Path>,
        com: Option<[f64; 3]>,
        pips: Option<[f64; 2]>,
        edge_radius: Option<f64>,
        shell: Option<[f64; 2]>,
        density: Option<f64>,
        read: ReadFile,
    ) -> Result<(Features, Option<f64>)> {
        let file = match file {
            Some(path) => DieFile::read(path, read)?,
            None => DieFile::default(),
        };
        let f = file.features()?.with_mm(com, pips, edge_radius, shell);
        Ok((f, density.or(file.density)))
    }
}

/// The largest mesh file read: 256 MiB (a printed die's STL is rarely above a few MiB).
pub const MAX_MESH_FILE: u64 = 256 << 20;

/// The die of any shape the front ends describe, if any: `name` (`--shape`, sized by
/// `size_mm`), or a die `file` that is a mesh (.obj, .stl) or a TOML die file naming one
/// (`mesh`, with its `scale`, `reads` and `labels`), the mesh's lengths times `scale` (the
/// file's, else 1). Both a name and a mesh, or a size or scale with nothing to size, are
/// refused with the reason.
pub fn described_shape(
    file: Option<&std::path::Path>,
    name: Option<&str>,
    size_mm: Option<f64>,
    scale: Option<f64>,
    read: ReadFile,
) -> Result<Option<Shape>> {
    let mesh = match file {
        Some(p) if is_mesh(p) => Some((p.to_path_buf(), DieFile::default())),
        Some(p) => {
            let f = DieFile::read(p, read)?;
            let dir = p.parent().unwrap_or(std::path::Path::new("."));
            let bad = |why: &str| Err(Error::field(Field::Die, p.display(), why.to_string()));
            if f.mesh.is_none() && (f.labels.is_some() || f.reads.is_some() || f.scale.is_some()) {
                return bad(
                    "labels, reads and scale describe a mesh: give its mesh (or leave them out)",
                );
            }
            if f.mesh.is_some() && (f.layout.is_some() || f.faces.is_some()) {
                return bad(
                    "layout and faces number a cuboid's faces; a mesh's faces show its labels",
                );
            }
            f.mesh.clone().map(|m| (dir.join(m), f))
        }
        None => None,
    };
    if let Some(s) = size_mm {
        if name.is_none() {
            return Err(Error::field(
                Field::Size,
                s,
                crate::text![
                    "sizes a named shape: give it with ",
                    Field::Shape,
                    " (a mesh is sized by ",
                    Field::Scale,
                    ")"
                ],
            ));
        }
        if !(s.is_finite() && s > 0.0) {
            return Err(Error::field(
                Field::Size,
                s,
                "must be a positive number of mm",
            ));
        }
    }
    if let Some(s) = scale {
        if !(s.is_finite() && s > 0.0) || mesh.is_none() {
            return Err(Error::field(
                Field::Scale,
                s,
                "must be a positive factor, with a mesh die file (--die FILE.obj|.stl)",
            ));
        }
    }
    match (name, mesh) {
        (Some(n), Some(_)) => Err(Error::field(
            Field::Shape,
            n,
            "give a named shape or a mesh die file (--die), not both",
        )),
        (Some(n), None) => shape::named(n, size_mm).map(Some),
        (None, None) => Ok(None),
        (None, Some((path, f))) => {
            // A mesh a die file names is refused naming the die file (the one the user gave).
            let toml = file.filter(|f| !is_mesh(f));
            from_mesh_file(&path, &f, toml, scale, read).map(Some)
        }
    }
}

/// The die of the mesh at `path`, with a die file's `f` (its scale, reads and labels; from
/// the file `toml`, if one named the mesh), its lengths times `scale` (else the file's, else
/// 1). A refusal names `toml` if given, and the mesh.
fn from_mesh_file(
    path: &std::path::Path,
    f: &DieFile,
    toml: Option<&std::path::Path>,
    scale: Option<f64>,
    read: ReadFile,
) -> Result<Shape> {
    let bytes = read(path, MAX_MESH_FILE)?;
    let file_name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into(),
    );
    let bad = |why: String| match toml {
        Some(toml) if why.starts_with(&file_name) => Error::field(Field::Die, toml.display(), why),
        Some(toml) => Error::field(Field::Die, toml.display(), format!("{file_name}: {why}")),
        None => Error::field(Field::Die, path.display(), why),
    };
    let mesh = crate::model::mesh_file::read_mesh(&bytes, &file_name).map_err(bad)?;
    let k = scale.or(f.scale).unwrap_or(1.0);
    if !(k.is_finite() && k > 0.0) {
        return Err(bad(format!("scale {k}: must be a positive factor")));
    }
    let labels = f.mesh_labels().map_err(bad)?;
    let name = format!(
        "{file_name}{} fnv1a64:{:016x}",
        if k == 1.0 {
            String::new()
        } else {
            format!(" ×{k}")
        },
        fnv64(&bytes)
    );
    let shape = shape::from_mesh(
        &mesh.scaled(k),
        name,
        labels.as_deref(),
        f.reads.unwrap_or(if f.labels.is_some() {
            shape::Reads::Up
        } else {
            shape::Reads::Down
        }),
    )
    .map_err(|e| match e.starts_with("its ") && e.contains(" size, ") {
        true => bad(format!("{e} (is the mesh in mm? --scale)")),
        false => bad(e),
    })?;
    // Every label given names a resting facet: one that names none is a mistake (a
    // normal mistyped, or a facet the die cannot rest on), not a label to drop.
    for (n, label) in labels.iter().flatten() {
        if !shape
            .faces
            .iter()
            .any(|f| Vector3::from(f.normal).dot(n) > 1.0 - 1e-6)
        {
            return Err(bad(format!(
                "label '{label}': its normal ({:.4}, {:.4}, {:.4}) is no resting facet's \
                 (the die rests on {} facets)",
                n.x,
                n.y,
                n.z,
                shape.faces.len()
            )));
        }
    }
    Ok(shape)
}

/// FNV-1a, 64 bits: a mesh file's fingerprint in the die's name (its geometry itself is in
/// the run's specification, under its checksum).
fn fnv64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}
