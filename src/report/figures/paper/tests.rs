//! Tests of `paper`.

use super::*;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh directory under the system temp dir, removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> TempDir {
        static N: AtomicUsize = AtomicUsize::new(0);
        let dir = std::env::temp_dir().join(format!(
            "dicephys-figures-{}-{}-{name}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&dir);
        TempDir(dir)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Checks that the tags of an XML document balance: every `<name ...>` is closed by
/// `</name>` in order, `<.../>` closes itself, `<?...?>` and `<!...>` are skipped, and the
/// root is `svg`. Returns the number of elements.
fn balanced(xml: &str) -> Result<usize, String> {
    let mut stack: Vec<&str> = Vec::new();
    let mut count = 0;
    let mut rest = xml;
    let mut saw_root = false;
    while let Some(i) = rest.find('<') {
        let after = &rest[i + 1..];
        let end = after.find('>').ok_or("unterminated tag")?;
        let tag = &after[..end];
        rest = &after[end + 1..];
        if tag.starts_with('?') || tag.starts_with('!') {
            continue;
        }
        if let Some(name) = tag.strip_prefix('/') {
            let open = stack.pop().ok_or(format!("</{name}> closes nothing"))?;
            if open != name.trim() {
                return Err(format!("<{open}> closed by </{name}>"));
            }
            continue;
        }
        let name = tag
            .split(|c: char| c.is_whitespace() || c == '/')
            .next()
            .unwrap_or("");
        if name.is_empty() {
            return Err(format!("bad tag <{tag}>"));
        }
        if stack.is_empty() {
            if saw_root {
                return Err("more than one root element".into());
            }
            if name != "svg" {
                return Err(format!("root is <{name}>, not <svg>"));
            }
            saw_root = true;
        }
        count += 1;
        if !tag.ends_with('/') {
            stack.push(name);
        }
    }
    if let Some(open) = stack.pop() {
        return Err(format!("<{open}> never closed"));
    }
    if !saw_root {
        return Err("no root element".into());
    }
    Ok(count)
}

/// Reads `<stem>.svg` and checks it and `<stem>.png`; returns the SVG text.
fn check_files(dir: &Path, stem: &str) -> String {
    let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap();
    let start = svg.trim_start();
    assert!(
        start.starts_with("<svg") || start.starts_with("<?xml"),
        "{stem}.svg starts {:?}",
        &start[..start.len().min(40)]
    );
    assert!(svg.contains("</svg>"));
    let n = balanced(&svg).unwrap_or_else(|e| panic!("{stem}.svg: {e}"));
    assert!(n > 20, "{stem}.svg has only {n} elements");
    let png = std::fs::read(dir.join(format!("{stem}.png"))).unwrap();
    assert!(
        png.starts_with(b"\x89PNG\r\n\x1a\n"),
        "{stem}.png is not a PNG"
    );
    assert!(png.len() > 5000, "{stem}.png is only {} bytes", png.len());
    svg
}

fn has_all(svg: &str, labels: &[&str]) {
    for l in labels {
        assert!(svg.contains(l), "no {l:?} in the SVG");
    }
}

fn sims() -> Vec<SimSeries> {
    let rs = [1.0 / 3.0, 0.379, 0.481, 0.591, 0.833];
    let series = |label: &str, two_d: bool, scale: f64| SimSeries {
        label: label.into(),
        two_d,
        points: rs
            .iter()
            .map(|&r| Point {
                x: r,
                y: scale * theory::ratio_from_r(r),
                y_err: 0.01,
            })
            .collect(),
    };
    vec![
        series("Bullet 2D", true, 1.3),
        series("Rapier 2D", true, 1.2),
        series("Bullet 3D", false, 1.1),
    ]
}

#[test]
fn master_graph_writes_both_files_with_every_series() {
    let dir = TempDir::new("master");
    master_graph(&dir.0, "master", &paper_experiment_points(), &sims()).unwrap();
    let svg = check_files(&dir.0, "master");
    has_all(
        &svg,
        &[
            "theory with bounces (the paper&apos;s eq. 8)",
            "theory without a bounce (eq. 1)",
            "pine blocks",
            "MDF",
            "tough carpet",
            "Bullet 2D",
            "Rapier 2D",
            "Bullet 3D",
            "±1σ",
            R_DESC,
            "P(breadth vertical) / P(width vertical)",
        ],
    );
    // Plain names in the legend, not the paper's LaTeX labels; the measurements drawn after
    // (above) the simulations, the legend in drawing order.
    assert!(!svg.contains("MasterEqu") && !svg.contains("InElasK"));
    assert!(svg.find("Bullet 3D").unwrap() < svg.find("pine blocks").unwrap());
}

#[test]
fn master_graph_draws_the_series_at_one_r_side_by_side() {
    // Two 2D simulations and one measurement at the same R and ratio: three circles, none on
    // another (before, all three at one x).
    let dir = TempDir::new("master-dodge");
    let at = |label: &str| SimSeries {
        label: label.into(),
        two_d: true,
        points: vec![Point {
            x: 0.5,
            y: 0.3,
            y_err: 0.0,
        }],
    };
    let exp = [ExpPoint {
        r: 0.5,
        ratio: 0.3,
        err: 0.0,
        set: "mdf".into(),
    }];
    master_graph(&dir.0, "dodge", &exp, &[at("a"), at("b")]).unwrap();
    let svg = check_files(&dir.0, "dodge");
    let mut xs: Vec<i64> = svg
        .split("<circle cx=\"")
        .skip(1)
        .filter_map(|c| {
            let (x, rest) = c.split_once('"')?;
            // The plotted markers, not the legend's (drawn in its box at the left).
            let y: i64 = rest
                .split_once("cy=\"")?
                .1
                .split_once('"')?
                .0
                .parse()
                .ok()?;
            (y > 300).then(|| x.parse().ok()).flatten()
        })
        .collect();
    xs.sort_unstable();
    assert_eq!(xs.len(), 3, "{xs:?}");
    for w in xs.windows(2) {
        assert!(w[1] - w[0] >= 4, "markers {xs:?} px: one hides another");
    }
    assert!(
        (xs[0] + xs[2] - 2 * xs[1]).abs() <= 1,
        "centred on the R: {xs:?}"
    );
}

#[test]
fn master_graph_survives_bad_and_empty_input() {
    let dir = TempDir::new("master-nan");
    let nan = f64::NAN;
    let exp = vec![
        ExpPoint {
            r: nan,
            ratio: 0.5,
            err: 0.1,
            set: "mdf".into(),
        },
        ExpPoint {
            r: 0.5,
            ratio: f64::INFINITY,
            err: nan,
            set: "pine".into(),
        },
        ExpPoint {
            r: 0.6,
            ratio: 0.2,
            err: f64::INFINITY,
            set: "Marble <&>".into(),
        },
    ];
    let sims = vec![
        SimSeries {
            label: "all NaN".into(),
            two_d: true,
            points: vec![Point {
                x: nan,
                y: nan,
                y_err: nan,
            }],
        },
        SimSeries {
            label: "empty 3D".into(),
            two_d: false,
            points: vec![],
        },
        SimSeries {
            label: "beyond one".into(),
            two_d: false,
            points: vec![Point {
                x: 1.4,
                y: 2.5,
                y_err: -1.0,
            }],
        },
    ];
    master_graph(&dir.0, "bad", &exp, &sims).unwrap();
    let svg = check_files(&dir.0, "bad");
    has_all(
        &svg,
        &["all NaN", "empty 3D", "beyond one", "Marble &lt;&amp;&gt;"],
    );
    master_graph(&dir.0, "empty", &[], &[]).unwrap();
    has_all(
        &check_files(&dir.0, "empty"),
        &["theory", "without a bounce"],
    );
}

#[test]
fn prob_2d_draws_theory_and_no_bounce() {
    let dir = TempDir::new("prob2d");
    prob_2d(&dir.0, "prob2d").unwrap();
    let svg = check_files(&dir.0, "prob2d");
    has_all(
        &svg,
        &[
            "P(K) = P(width vertical), theory",
            "P(L) = P(breadth vertical), theory",
            "P(width vertical), no bounce",
            "P(breadth vertical), no bounce",
        ],
    );
}

#[test]
fn len_graph_draws_the_papers_groups() {
    let dir = TempDir::new("len");
    // A directory that does not exist yet is created.
    let nested = dir.0.join("a").join("b");
    len_graph(&nested, "len", &paper_length_groups()).unwrap();
    let svg = check_files(&nested, "len");
    has_all(
        &svg,
        &[
            "pine 25x18 on Carpet",
            "printed 24x20 on MDF",
            "printed 22x13 on MDF",
            "block length (mm)",
        ],
    );
    let bad = vec![
        LenGroup {
            label: "NaN group".into(),
            points: vec![Point {
                x: f64::NAN,
                y: 0.3,
                y_err: 0.1,
            }],
        },
        LenGroup {
            label: "empty group".into(),
            points: vec![],
        },
    ];
    len_graph(&dir.0, "len-bad", &bad).unwrap();
    has_all(
        &check_files(&dir.0, "len-bad"),
        &["NaN group", "empty group"],
    );
    len_graph(&dir.0, "len-none", &[]).unwrap();
    check_files(&dir.0, "len-none");
}

#[test]
fn dreidel_draws_exact_and_first_order() {
    let dir = TempDir::new("dreidel");
    dreidel(&dir.0, "dreidel", 0.1).unwrap();
    let svg = check_files(&dir.0, "dreidel");
    has_all(
        &svg,
        &[
            "each long side (l), exact",
            "each short side (k), exact",
            "each long side, first order",
            "each short side, first order",
        ],
    );
    // Far beyond first order's range: still drawn.
    dreidel(&dir.0, "dreidel-wide", 5.0).unwrap();
    check_files(&dir.0, "dreidel-wide");
    for bad in [f64::NAN, 0.0, -0.1, f64::INFINITY] {
        assert!(dreidel(&dir.0, "no", bad).is_err(), "{bad}");
    }
}

#[test]
fn bad_stem_is_an_error() {
    let dir = TempDir::new("stem");
    assert!(prob_2d(&dir.0, "").is_err());
    assert!(prob_2d(&dir.0, "a/b").is_err());
}

#[test]
fn paper_points_are_the_coloured_rows() {
    let pts = paper_experiment_points();
    assert_eq!(pts.len(), 15);
    for set in ["pine", "mdf", "carpet"] {
        assert_eq!(pts.iter().filter(|p| p.set == set).count(), 5, "{set}");
    }
    // Row 7: 140x24x20 printed on MDF, 361 breadth vertical, 639 width vertical.
    let p = &pts[5];
    assert_eq!(p.set, "mdf");
    assert!((p.r - 20.0 / 24.0).abs() < 1e-12);
    assert!((p.ratio - 361.0 / 639.0).abs() < 1e-12);
    let want = (361.0f64 * 639.0 * 1000.0 / 639f64.powi(4)).sqrt();
    assert!((p.err - want).abs() < 1e-12);
    assert!(pts
        .iter()
        .all(|p| p.r > 0.0 && p.r <= 1.0 && p.ratio.is_finite() && p.err > 0.0));
}

#[test]
fn paper_length_groups_are_the_three_sets() {
    let groups = paper_length_groups();
    let summary: Vec<(&str, Vec<f64>)> = groups
        .iter()
        .map(|g| (g.label.as_str(), g.points.iter().map(|p| p.x).collect()))
        .collect();
    assert_eq!(
        summary,
        vec![
            ("pine 25x18 on Carpet", vec![782.0, 98.0]),
            ("printed 24x20 on MDF", vec![140.0, 100.0, 80.0]),
            ("printed 22x13 on MDF", vec![140.0, 80.0]),
        ]
    );
    // Row 11: 80 mm 22x13 on MDF, 84/416.
    assert!((groups[2].points[1].y - 84.0 / 416.0).abs() < 1e-12);
}

#[test]
fn tick_labels_drop_trailing_zeros() {
    assert_eq!(tick(&100.0), "100");
    assert_eq!(tick(&0.0), "0");
    assert_eq!(tick(&-0.0), "0");
    assert_eq!(tick(&0.1), "0.1");
    assert_eq!(tick(&(0.1 + 0.2)), "0.3");
    assert_eq!(tick(&0.25), "0.25");
    assert_eq!(tick(&-2.5), "-2.5");
}

#[test]
fn tag_check_catches_broken_xml() {
    assert_eq!(
        balanced("<svg a=\"1\"><g><path d=\"M 1\"/></g></svg>"),
        Ok(3)
    );
    assert!(balanced("<?xml version=\"1.0\"?>\n<svg></svg>").is_ok());
    assert!(balanced("<svg><g></svg>").is_err());
    assert!(balanced("<svg><g>").is_err());
    assert!(balanced("<svg></svg><svg></svg>").is_err());
    assert!(balanced("<html></html>").is_err());
    assert!(balanced("<svg><text>a").is_err());
}
