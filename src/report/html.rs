//! `report.html` beside `report.md`: the Markdown the program writes, as one page to read in a
//! browser: its sections linked from a list at the top, its tables, and each figure it refers
//! to (`![…](stem.svg)` or `stem.png`) inlined as its SVG, so the page stands alone.

use pulldown_cmark::{CowStr, Event, HeadingLevel, Options, Parser, Tag, TagEnd};
use std::path::Path;

const STYLE: &str = "body{font:15px/1.5 'DejaVu Sans',system-ui,sans-serif;color:#222;\
max-width:1100px;margin:0 auto;padding:12px 20px 40px;background:#fbfbf9}\
h1{font-size:22px}h2{font-size:18px;border-bottom:1px solid #ccc;margin-top:1.6em}\
h3{font-size:16px}nav{background:#f0f0ea;border:1px solid #ddd;padding:6px 14px;\
font-size:14px}nav ul{margin:4px 0;padding-left:18px}\
table{border-collapse:collapse;margin:8px 0;font-size:13px;font-variant-numeric:tabular-nums}\
th,td{border:1px solid #ccc;padding:3px 7px;text-align:right}th{background:#eee}\
td:first-child,th:first-child{text-align:left}code{background:#f0f0ea;padding:0 3px}\
pre{background:#f0f0ea;padding:8px;overflow-x:auto}\
figure{margin:12px 0}figure svg{max-width:100%;height:auto;background:#fff}\
figcaption{font-size:13px;color:#555}";

/// Written into the page: every error, a figure that does not load included, is kept on
/// `<body data-errors>` (where the tests read it) and shown.
const ERRORS: &str = "<script>window.addEventListener('error',function(e){var b=document.body;\
var m=e.message||('cannot load '+(e.target&&(e.target.src||e.target.href)));\
b.dataset.errors=(b.dataset.errors?b.dataset.errors+'\\n':'')+m;},true);</script>";

/// The page for `markdown`, whose figures are in `dir`.
pub fn page(markdown: &str, dir: &Path) -> String {
    let mut events: Vec<Event> = Parser::new_ext(markdown, Options::ENABLE_TABLES).collect();
    let sections = anchor_headings(&mut events);
    let (events, figures) = inline_figures(events, dir);
    let mut body = String::new();
    pulldown_cmark::html::push_html(&mut body, events.into_iter());
    let title = sections
        .iter()
        .find(|s| s.0 == 1)
        .map_or("dicephys report", |s| s.2.as_str());
    // The list of sections under the title (verdict first, as the Markdown has it).
    let nav = contents(&sections);
    match body.find("</h1>\n") {
        Some(at) => body.insert_str(at + 6, &nav),
        None => body.insert_str(0, &nav),
    }
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{STYLE}</style>\n{ERRORS}\n</head>\n\
         <body data-errors=\"\" data-figures=\"{figures}\">\n{body}</body>\n</html>\n",
        crate::report::view::escape(title),
    )
}

/// Writes `report.md` and `report.html` into `dir` for a command whose report is the text it
/// prints (`fair --out`): `title`, the `text` as it is, then the figures `stems` that are in
/// `dir` (`stem.svg`).
pub fn write_text_report(dir: &Path, title: &str, text: &str, stems: &[&str]) -> crate::Result<()> {
    let mut md = format!("# {title}\n\n```\n{}\n```\n", text.trim_end());
    for stem in stems {
        if dir.join(format!("{stem}.svg")).is_file() {
            md += &format!("\n![{stem}]({stem}.svg)\n");
        }
    }
    crate::run::io::write_atomic(&dir.join("report.md"), md.as_bytes())?;
    crate::run::io::write_atomic(&dir.join("report.html"), page(&md, dir).as_bytes())
}

/// Gives each heading an id from its text (unique on the page); the headings as (level, id,
/// text).
fn anchor_headings(events: &mut [Event]) -> Vec<(u8, String, String)> {
    let mut out: Vec<(u8, String, String)> = Vec::new();
    let mut i = 0;
    while i < events.len() {
        if let Event::Start(Tag::Heading { level, .. }) = &events[i] {
            let level = heading_number(*level);
            let mut text = String::new();
            let mut j = i + 1;
            while !matches!(events.get(j), Some(Event::End(TagEnd::Heading(_))) | None) {
                if let Event::Text(t) | Event::Code(t) = &events[j] {
                    text.push_str(t);
                }
                j += 1;
            }
            let base = slug(&text);
            let mut id = base.clone();
            let mut n = 1;
            while out.iter().any(|s| s.1 == id) {
                n += 1;
                id = format!("{base}-{n}");
            }
            if let Event::Start(Tag::Heading { id: slot, .. }) = &mut events[i] {
                *slot = Some(CowStr::from(id.clone()));
            }
            out.push((level, id, text));
            i = j;
        }
        i += 1;
    }
    out
}

fn heading_number(l: HeadingLevel) -> u8 {
    l as u8
}

/// Lower case letters and digits, runs of anything else one `-`.
fn slug(text: &str) -> String {
    let mut s = String::new();
    for c in text.chars().flat_map(char::to_lowercase) {
        if c.is_alphanumeric() {
            s.push(c);
        } else if !s.ends_with('-') {
            s.push('-');
        }
    }
    let s = s.trim_matches('-').to_string();
    if s.is_empty() {
        "section".into()
    } else {
        s
    }
}

/// The list of the sections below the title, each a link.
fn contents(sections: &[(u8, String, String)]) -> String {
    let items: Vec<String> = sections
        .iter()
        .filter(|s| s.0 == 2)
        .map(|(_, id, text)| {
            format!(
                "<li><a href=\"#{id}\">{}</a></li>",
                crate::report::view::escape(text)
            )
        })
        .collect();
    if items.len() < 2 {
        return String::new();
    }
    format!(
        "<nav><strong>Sections</strong><ul>{}</ul></nav>\n",
        items.concat()
    )
}

/// Each image whose SVG is in `dir` (the image's stem with `.svg`) as that SVG, in a figure
/// captioned with its alternative text; the events and how many were inlined.
fn inline_figures<'a>(events: Vec<Event<'a>>, dir: &Path) -> (Vec<Event<'a>>, usize) {
    let mut out = Vec::with_capacity(events.len());
    let mut figures = 0;
    let mut it = events.into_iter();
    while let Some(e) = it.next() {
        let Event::Start(Tag::Image { dest_url, .. }) = &e else {
            out.push(e);
            continue;
        };
        let Some(svg) = svg_beside(dir, dest_url) else {
            out.push(e);
            continue;
        };
        let mut alt = String::new();
        for inner in it.by_ref() {
            match inner {
                Event::End(TagEnd::Image) => break,
                Event::Text(t) => alt.push_str(&t),
                _ => {}
            }
        }
        figures += 1;
        out.push(Event::InlineHtml(CowStr::from(format!(
            "<figure>{svg}<figcaption>{}</figcaption></figure>",
            crate::report::view::escape(&alt)
        ))));
    }
    (out, figures)
}

/// The SVG of the figure `url` names (a file name in `dir`, `.svg` or `.png`), from its
/// `<svg` on, if it is there.
fn svg_beside(dir: &Path, url: &str) -> Option<String> {
    if url.contains('/') || url.contains(':') {
        return None;
    }
    let stem = url
        .strip_suffix(".svg")
        .or_else(|| url.strip_suffix(".png"))?;
    let text = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).ok()?;
    let at = text.find("<svg")?;
    Some(text[at..].to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headings_get_unique_ids_and_figures_are_inlined() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("g.svg"),
            "<?xml version=\"1.0\"?>\n<svg width=\"10\" height=\"10\"></svg>",
        )
        .unwrap();
        let md = "# Title\n\n## A b\n\ntext\n\n## A b\n\n![the g](g.png)\n\n![gone](h.svg)\n\n\
                  | x | y |\n|---|---|\n| 1 | 2 |\n";
        let html = page(md, dir.path());
        assert!(html.contains("<h2 id=\"a-b\">"), "{html}");
        assert!(html.contains("<h2 id=\"a-b-2\">"), "{html}");
        assert!(html.contains("<a href=\"#a-b-2\">"), "{html}");
        assert!(html.contains("<figure><svg width=\"10\""), "{html}");
        assert!(html.contains("<figcaption>the g</figcaption>"), "{html}");
        assert!(html.contains("<img src=\"h.svg\""), "{html}");
        assert!(html.contains("data-figures=\"1\""), "{html}");
        assert!(html.contains("<table>"), "{html}");
        assert!(html.contains("<title>Title</title>"), "{html}");
    }
}
