//! The pages the program writes, opened in a real browser: Debian's Chromium, headless, with
//! the network off (a proxy that is not there; and no http(s) address in the page). The
//! trace's viewer (`trace --html`): no errors, the animation ends on the face `trace` reports,
//! and a screenshot shows the die where the trace has it. Without Chromium the tests say they
//! are skipped; under CI (`CI` set: `.ci/run` installs it) they fail.

use crate::helpers::{bin, Scratch};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The browser, if there is one on the PATH; else the test is skipped (failed under CI).
pub fn chromium(test: &str) -> Option<PathBuf> {
    let found = std::env::var_os("PATH").and_then(|p| {
        std::env::split_paths(&p)
            .flat_map(|d| ["chromium", "chromium-browser"].map(|n| d.join(n)))
            .find(|f| f.is_file())
    });
    if found.is_none() {
        let why = "no chromium here (apt-get install chromium)";
        if std::env::var_os("CI").is_some() {
            panic!("{test}: {why}, and CI is set: .ci/run installs it");
        }
        use std::io::Write;
        let _ = writeln!(std::io::stderr(), "\n{test}: SKIPPED: {why}");
    }
    found
}

/// The window the pages are opened in, CSS px at a device scale of 1.
pub const WINDOW: (u32, u32) = (1100, 800);

/// Runs headless Chromium on `page` (a file, with `fragment` after `#`), offline, in a
/// profile of its own, with `what` (`--dump-dom`, `--screenshot=…`); its stdout. A hang is
/// cut off after two minutes (a guard, not a measure: the page opens in well under a second).
pub fn headless(browser: &Path, page: &Path, fragment: &str, what: &str) -> String {
    let profile = Scratch::new("chromium-profile");
    let url = format!("file://{}#{fragment}", page.display());
    let mut child = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--proxy-server=127.0.0.1:9",
            "--force-device-scale-factor=1",
            "--hide-scrollbars",
            "--virtual-time-budget=10000",
            &format!("--window-size={},{}", WINDOW.0, WINDOW.1),
            &format!("--user-data-dir={}", profile.display()),
            what,
            &url,
        ])
        .current_dir(profile.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("run chromium");
    let mut stdout = child.stdout.take().expect("stdout");
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut stdout, &mut s).map(|_| s)
    });
    let start = Instant::now();
    while child.try_wait().expect("wait for chromium").is_none() {
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("chromium did not finish with {url} in two minutes");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    reader.join().unwrap().expect("chromium's output")
}

/// `<body>`'s attribute `name` in a dumped DOM (the pages keep their state there).
pub fn body_attr(dom: &str, name: &str) -> Option<String> {
    let tag = &dom[dom.find("<body")?..];
    let tag = &tag[..tag.find('>')?];
    let at = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    let value = &tag[at..];
    Some(
        value[..value.find('"')?]
            .replace("&quot;", "\"")
            .replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&amp;", "&"),
    )
}

/// Every http(s) address in `text` but XML namespaces (XHTML's, SVG's, XLink's: names, never
/// fetched).
pub fn addresses(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for start in ["http://", "https://"] {
        for (at, _) in text.match_indices(start) {
            let rest = &text[at..];
            let end = rest
                .find(|c: char| c.is_whitespace() || "\"'()<>`".contains(c))
                .unwrap_or(rest.len());
            let address = &rest[..end];
            let namespaces = [
                "http://www.w3.org/1999/xhtml",
                "http://www.w3.org/2000/svg",
                "http://www.w3.org/1999/xlink",
            ];
            if !namespaces.contains(&address) {
                out.push(address.to_string());
            }
        }
    }
    out
}

/// `trace --html` of the d20's throw 0 of seed 1 into `dir`; the page and trace's stderr.
fn d20_page(dir: &Path) -> (PathBuf, String) {
    let page = dir.join("t.html");
    let out = bin()
        .args([
            "trace", "--shape", "d20", "--seed", "1", "--index", "0", "--html",
        ])
        .arg(&page)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "trace --html failed: {err}");
    assert!(out.stdout.is_empty(), "with --html no CSV is printed");
    (page, err)
}

#[test]
fn the_trace_page_opens_offline_and_ends_on_the_face_trace_reports() {
    let Some(browser) = chromium("the_trace_page_opens_offline_and_ends_on_the_face_trace_reports")
    else {
        return;
    };
    let dir = Scratch::new("browser-trace");
    let (page, err) = d20_page(&dir);
    let html = std::fs::read_to_string(&page).unwrap();
    assert_eq!(
        addresses(&html),
        Vec::<String>::new(),
        "the page names no address to fetch"
    );
    // trace's line: "throw 0: … settled, showing 7 after N steps".
    let face = err
        .split("showing ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .unwrap_or_else(|| panic!("no face in trace's line: {err}"));
    for (fragment, renderer) in [("t=end", "webgl"), ("t=end&2d", "canvas2d")] {
        let dom = headless(&browser, &page, fragment, "--dump-dom");
        assert_eq!(
            body_attr(&dom, "data-ready").as_deref(),
            Some("1"),
            "{fragment}: the page did not finish: {dom:.2000}"
        );
        assert_eq!(
            body_attr(&dom, "data-errors").as_deref(),
            Some(""),
            "{fragment}: errors"
        );
        assert_eq!(body_attr(&dom, "data-renderer").as_deref(), Some(renderer));
        assert_eq!(
            body_attr(&dom, "data-final-face").as_deref(),
            Some(face),
            "{fragment}: the last frame's face"
        );
        assert_eq!(
            body_attr(&dom, "data-outcome").as_deref(),
            Some(face),
            "{fragment}: the outcome the page was given"
        );
        assert_eq!(
            body_attr(&dom, "data-face-now").as_deref(),
            Some(face),
            "{fragment}: the face shown at the end"
        );
    }
}

/// The share of the pixels within `radius` of (x, y) that are the die's red (throw 0's colour,
/// lit or shaded: red well above green and blue; its white labels are not).
fn red_share(png: &Path, (x, y): (f64, f64), radius: f64) -> f64 {
    let img = image::open(png).expect("a PNG").to_rgb8();
    let (mut red, mut all) = (0u32, 0u32);
    for (px, py, p) in img.enumerate_pixels() {
        if (px as f64 - x).hypot(py as f64 - y) <= radius {
            all += 1;
            let [r, g, b] = p.0.map(i32::from);
            if r > 60 && 10 * r > 18 * g && 10 * r > 18 * b {
                red += 1;
            }
        }
    }
    f64::from(red) / f64::from(all.max(1))
}

/// A screenshot of `page` at `fragment` (its DOM `dom`, dumped): the die's centre on screen as
/// the page gives it, and the share of its red within 12 px of it and 150 px to its right.
fn red_about_the_die(
    browser: &Path,
    page: &Path,
    dir: &Path,
    fragment: &str,
    dom: &str,
) -> ((f64, f64), f64, f64) {
    let centre = body_attr(dom, "data-centre").expect("the page gives the die's centre");
    let (x, y) = centre.split_once(',').expect("x,y");
    let (x, y): (f64, f64) = (x.parse().unwrap(), y.parse().unwrap());
    let shot = dir.join(format!("{}.png", fragment.replace(['=', '&'], "-")));
    headless(
        browser,
        page,
        fragment,
        &format!("--screenshot={}", shot.display()),
    );
    let near = red_share(&shot, (x, y), 12.0);
    let far = red_share(&shot, (x + 150.0, y), 12.0);
    eprintln!("{fragment}: red at the die's centre {near:.2}, 150 px away {far:.2}");
    ((x, y), near, far)
}

#[test]
fn a_screenshot_shows_the_die_where_the_trace_has_it() {
    let Some(browser) = chromium("a_screenshot_shows_the_die_where_the_trace_has_it") else {
        return;
    };
    let dir = Scratch::new("browser-shot");
    let (page, _) = d20_page(&dir);
    for fragment in ["t=0.25", "t=end", "t=0.25&2d"] {
        let dom = headless(&browser, &page, fragment, "--dump-dom");
        let ((x, y), near, far) = red_about_the_die(&browser, &page, &dir, fragment, &dom);
        assert!(
            (0.0..f64::from(WINDOW.0)).contains(&x) && (0.0..f64::from(WINDOW.1)).contains(&y),
            "{fragment}: the die's centre ({x}, {y}) is off the screen"
        );
        assert!(
            near > 0.35,
            "{fragment}: {near:.2} of the pixels at the die's centre ({x}, {y}) are its red"
        );
        assert!(
            far < 0.05,
            "{fragment}: {far:.2} of the pixels 150 px from the die are red"
        );
    }
}

/// report.html of `paper`, `fair --out` and `fit`, small runs, each opened offline: no errors
/// (a figure that does not load is one), every figure report.md names inlined as SVG, every
/// link to a section leading to one.
#[test]
fn the_reports_open_offline_with_their_figures_inline() {
    let Some(browser) = chromium("the_reports_open_offline_with_their_figures_inline") else {
        return;
    };
    let dir = Scratch::new("browser-reports");
    let runs: [(&str, &[&str]); 3] = [
        ("paper", &["paper", "--rolls", "40", "--seed", "3"]),
        (
            "fair",
            &["fair", "--shape", "d6", "--rolls", "300", "--seed", "3"],
        ),
        (
            "fit",
            &[
                "fit",
                "--data",
                "paper",
                "--free",
                "e",
                "--dt",
                "1/250",
                "--no-refine",
                "--points",
                "6",
                "--rolls",
                "40",
                "--degree",
                "1",
            ],
        ),
    ];
    for (name, args) in runs {
        let out_dir = dir.join(name);
        let out = bin()
            .args(args)
            .arg("--out")
            .arg(&out_dir)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let md = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
        let html = std::fs::read_to_string(out_dir.join("report.html")).unwrap();
        assert_eq!(
            addresses(&html),
            Vec::<String>::new(),
            "{name}: no address to fetch"
        );
        let figures = md.matches("![").count();
        assert!(figures >= 1, "{name}: report.md names no figure");
        assert_eq!(
            html.matches("<figure><svg").count(),
            figures,
            "{name}: each figure inlined"
        );
        for link in html.split("href=\"#").skip(1) {
            let id = &link[..link.find('"').unwrap()];
            assert!(
                html.contains(&format!(" id=\"{id}\"")),
                "{name}: #{id} leads nowhere"
            );
        }
        let dom = headless(&browser, &out_dir.join("report.html"), "", "--dump-dom");
        assert_eq!(
            body_attr(&dom, "data-errors").as_deref(),
            Some(""),
            "{name}: errors"
        );
        assert_eq!(
            body_attr(&dom, "data-figures"),
            Some(figures.to_string()),
            "{name}: the figures"
        );
        assert_eq!(
            dom.matches("<svg").count(),
            figures,
            "{name}: the figures in the page"
        );
    }
}

/// A box with pips and rounded edges (issue 74: "the die as it is"): its page opens offline in
/// both renderers with no error, ends on the side `trace` names, and shows the die (its red)
/// where the page puts its centre; the pips and the rounding's geometry are checked against
/// their closed forms in `report::view::die`'s tests.
#[test]
fn a_box_with_pips_and_rounded_edges_opens_and_ends_on_its_side() {
    let Some(browser) = chromium("a_box_with_pips_and_rounded_edges_opens_and_ends_on_its_side")
    else {
        return;
    };
    let dir = Scratch::new("browser-box");
    let page = dir.join("box.html");
    let out = bin()
        .args([
            "trace",
            "--block",
            "16x16x16",
            "--pips",
            "3,0.5",
            "--edge-radius",
            "1",
            "--seed",
            "1",
            "--index",
            "0",
            "--html",
        ])
        .arg(&page)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "trace --html failed: {err}");
    // trace's line: "throw 0: … settled, breadth vertical after N steps".
    let side = err
        .split("settled, ")
        .nth(1)
        .and_then(|s| s.split(" after").next())
        .unwrap_or_else(|| panic!("no side in trace's line: {err}"));
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(
        html.contains("\"pip_radius\":0.0015"),
        "the page has the pips"
    );
    for fragment in ["t=end", "t=end&2d"] {
        let dom = headless(&browser, &page, fragment, "--dump-dom");
        assert_eq!(
            body_attr(&dom, "data-ready").as_deref(),
            Some("1"),
            "{fragment}: {dom:.2000}"
        );
        assert_eq!(
            body_attr(&dom, "data-errors").as_deref(),
            Some(""),
            "{fragment}: errors"
        );
        assert_eq!(
            body_attr(&dom, "data-final-face").as_deref(),
            Some(side),
            "{fragment}"
        );
        // The pips (white) cover part of the faces about the centre: a lower share than a
        // plain die's 0.35, still far above the floor's none.
        let (_, near, far) = red_about_the_die(&browser, &page, &dir, fragment, &dom);
        assert!(
            near > 0.2,
            "{fragment}: {near:.2} of the pixels at the die's centre are its red"
        );
        assert!(
            far < 0.05,
            "{fragment}: {far:.2} of the pixels 150 px away are red"
        );
    }
}
