//! The die as it is described: what it departs from the ideal block by (`Features`), its
//! insert and pips, the standard pips' pattern, and the features a front end's options give.

use crate::model::faces::Layout;
use serde::{Deserialize, Serialize};

/// How the die departs from the paper's ideal block: uniform, sharp, plain. Each is off by
/// default, and a die with none of them is rolled on exactly the paper's path.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Features {
    /// The centre of mass, given outright: its offset from the geometric centre, m, in body
    /// axes (x breadth, y width, z length). The second moments about the geometric centre
    /// stay the solid's (a weight hidden inside moves the centre; what it does to the
    /// inertia is the die file's business). `None`: the solid's own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub com: Option<[f64; 3]>,
    /// Pips drilled in the standard pattern, one to six on the faces the layout numbers.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pips: Option<Pips>,
    /// Edges and corners rounded with this radius, m (0: sharp).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub edge_radius: f64,
    /// Which number is on which face (it decides where the pips are): `roll --layout`.
    #[serde(default, skip_serializing_if = "is_right")]
    pub layout: Layout,
    /// A block of a second material inside the die (a weight hidden on purpose).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub insert: Option<Insert>,
    /// The inertia tensor about the centre of mass, given outright (kg m², body axes: xx, yy,
    /// zz, xy, xz, yz), in place of the solid's; its principal frame is found from it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia: Option<[f64; 6]>,
    /// A printed die: a solid outer wall and a sparse infill inside it (`None`: solid
    /// throughout).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shell: Option<Shell>,
}

/// A 3D-printed die's build: a solid wall `wall` thick under every face, and inside it an
/// infill that fills the fraction `infill` of the volume (the slicer's infill density). Its
/// mass moments are ρ·[M(die) − (1 − infill)·M(inner)], the inner solid the die offset inward
/// by `wall`: an asymmetric die's centre of mass and inertia move from the uniform solid's.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shell {
    /// The wall's thickness, m.
    pub wall: f64,
    /// The infill's volume fraction in [0, 1] (1: the uniform solid, 0: a hollow shell).
    pub infill: f64,
}

/// The wall a fit's free infill is given on a die that has no shell of its own: 1 mm, a
/// slicer's usual outer wall (two to three perimeters).
pub const DEFAULT_WALL: f64 = 0.001;

/// A cuboid of another density inside the die, its edges along the die's axes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Insert {
    /// Its sides along x, y, z, m.
    pub size: [f64; 3],
    /// Its centre, m from the die's geometric centre, body axes.
    pub centre: [f64; 3],
    /// Its density, kg/m³ (0: a hollow).
    pub density: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn is_right(l: &Layout) -> bool {
    *l == Layout::Right
}

/// The shape of a pip's cavity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PipShape {
    /// A spherical cap: the drill's round end (depth at most half the diameter).
    #[default]
    Cap,
    /// A flat-bottomed cylinder.
    Cylinder,
}

/// Drilled pips. They change the mass, not the collision surface: a pip is narrower than
/// anything the floor could reach into.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pips {
    /// The pip's diameter on the face, m.
    pub diameter: f64,
    /// Its depth, m.
    pub depth: f64,
    /// Cap or cylinder.
    #[serde(default)]
    pub shape: PipShape,
    /// The paint filling the pips, kg/m³ (0: empty).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub fill_density: f64,
    /// The off-centre pips sit this fraction of the face's side from its centre along each
    /// face axis (standard dice: about a quarter).
    #[serde(default = "quarter")]
    pub spacing: f64,
}

fn quarter() -> f64 {
    0.25
}

impl Pips {
    /// Empty spherical caps `diameter` across and `depth` deep (m), at the standard spacing:
    /// what `--pips D,H` drills.
    pub fn caps(diameter: f64, depth: f64) -> Pips {
        Pips {
            diameter,
            depth,
            shape: PipShape::Cap,
            fill_density: 0.0,
            spacing: quarter(),
        }
    }
}

/// The pips on a face carrying `n`, in units of the spacing along the face's two axes.
pub fn pattern(n: u8) -> &'static [(f64, f64)] {
    match n {
        1 => &[(0.0, 0.0)],
        2 => &[(1.0, 1.0), (-1.0, -1.0)],
        3 => &[(1.0, 1.0), (0.0, 0.0), (-1.0, -1.0)],
        4 => &[(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)],
        5 => &[
            (1.0, 1.0),
            (1.0, -1.0),
            (0.0, 0.0),
            (-1.0, 1.0),
            (-1.0, -1.0),
        ],
        _ => &[
            (1.0, -1.0),
            (1.0, 0.0),
            (1.0, 1.0),
            (-1.0, -1.0),
            (-1.0, 0.0),
            (-1.0, 1.0),
        ],
    }
}

impl Features {
    /// These features with the ones given in mm (the command line's and the Python
    /// package's units) laid over them: a centre of mass, pips' diameter and depth (on the
    /// pips already here, keeping their shape, paint and spacing, or as empty caps), an edge
    /// radius, a shell (its wall in mm, its infill a fraction).
    pub fn with_mm(
        mut self,
        com: Option<[f64; 3]>,
        pips: Option<[f64; 2]>,
        edge_radius: Option<f64>,
        shell: Option<[f64; 2]>,
    ) -> Features {
        if let Some(c) = com {
            self.com = Some(c.map(|x| x / 1000.0));
        }
        if let Some([d, h]) = pips {
            let (d, h) = (d / 1000.0, h / 1000.0);
            self.pips = Some(match self.pips.take() {
                Some(p) => Pips {
                    diameter: d,
                    depth: h,
                    ..p
                },
                None => Pips::caps(d, h),
            });
        }
        if let Some(r) = edge_radius {
            self.edge_radius = r / 1000.0;
        }
        if let Some([wall, infill]) = shell {
            self.shell = Some(Shell {
                wall: wall / 1000.0,
                infill,
            });
        }
        self
    }

    /// These features with the centre of mass on `axis` (0 x, 1 y, 2 z) given outright at `m`
    /// metres from the geometric centre, its other components the ones given, else 0.
    pub fn with_com_on(mut self, axis: usize, m: f64) -> Features {
        let mut c = self.com.unwrap_or([0.0; 3]);
        c[axis] = m;
        self.com = Some(c);
        self
    }

    /// These features with the pips `m` metres deep; `None` if the die has no pips.
    pub fn with_pip_depth(mut self, m: f64) -> Option<Features> {
        self.pips.as_mut()?.depth = m;
        Some(self)
    }

    /// These features with the infill fraction `f`, in the die's own shell, or in a
    /// [`DEFAULT_WALL`] one if it has none (a fit's free infill).
    pub fn with_infill(mut self, f: f64) -> Features {
        let wall = self.shell.map_or(DEFAULT_WALL, |s| s.wall);
        self.shell = Some(Shell { wall, infill: f });
        self
    }

    /// True if nothing is set, not even the layout.
    pub fn is_default(&self) -> bool {
        *self == Features::default()
    }

    /// True if the die is the paper's ideal block.
    pub fn plain(&self) -> bool {
        self.com.is_none()
            && self.pips.is_none()
            && self.edge_radius == 0.0
            && self.insert.is_none()
            && self.inertia.is_none()
            && self.shell.is_none()
    }
}
