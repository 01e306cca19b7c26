//! The page's HTML: head and style, the 3D view's frame (list, slider,
//! read-out), the report's tables and figures, the embedded data, three.js
//! and the page's script. Nothing depends on the time or the machine: a
//! folder written twice holds the same page.

use super::Page;
use super::assets::{self, has_three};
use super::encode::{base64, html, json_script, script};
use crate::error::Result;
use std::fmt::Write as _;

/// An HTML table: a caption, header cells and rows of cells (text,
/// escaped here).
#[must_use]
pub fn table(caption: &str, header: &[&str], rows: &[Vec<String>]) -> String {
    let mut s = format!("<table><caption>{}</caption><thead><tr>", html(caption));
    for h in header {
        let _ = write!(s, "<th>{}</th>", html(h));
    }
    s += "</tr></thead><tbody>";
    for r in rows {
        s += "<tr>";
        for c in r {
            let _ = write!(s, "<td>{}</td>", html(c));
        }
        s += "</tr>";
    }
    s + "</tbody></table>\n"
}

/// A figure: the PNG at `path` embedded with its caption; `None` when the
/// file cannot be read.
#[must_use]
pub fn figure(caption: &str, path: &std::path::Path) -> Option<(String, Vec<u8>)> {
    std::fs::read(path).ok().map(|b| (caption.to_string(), b))
}

/// The embedded modules: `<script type="text/plain">` elements the boot
/// script imports through blob URLs.
fn modules() -> String {
    let mut s = String::new();
    for (id, text) in [
        ("three-core", assets::THREE_CORE),
        ("three-module", assets::THREE_MODULE),
        ("three-orbit", assets::ORBIT_CONTROLS),
        ("page-module", assets::PAGE_JS),
    ] {
        let _ = write!(
            s,
            "<script type=\"text/plain\" id=\"{id}\">{}</script>\n",
            script(text)
        );
    }
    s
}

/// The whole page.
pub(super) fn page(p: &Page) -> Result<String> {
    let data = serde_json::to_string(p)
        .map_err(|e| crate::Error::Invalid(format!("index.html's data: {e}")))?;
    let title = html(&p.title);
    let mut s = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>{title}</title>\n<style>{}</style></head>\n<body>\n<h1>{title}</h1>\n",
        assets::PAGE_CSS
    );
    s += "<div id=\"view3d\"><div id=\"side\"><div id=\"controls\"><button id=\"play\" type=\"button\">play the tour</button> <input id=\"slider\" type=\"range\" min=\"0\" max=\"0\" step=\"1\" value=\"0\" aria-label=\"pose\"> <span id=\"shown\"></span></div><ol id=\"poses\"></ol><div id=\"legend\"></div></div><div id=\"canvas\"></div></div>\n";
    if !has_three() {
        s += "<p class=\"warn\" id=\"no3d\">The 3D view is not in this page: the activecal that wrote it was built without three.js (run <code>scripts/setup</code>, which installs it into <code>web/node_modules</code>, and build again).</p>\n";
    }
    if !p.notes.is_empty() {
        s += "<ul class=\"notes\">";
        for n in &p.notes {
            let _ = write!(s, "<li>{}</li>", html(n));
        }
        s += "</ul>\n";
    }
    s += "<pre id=\"readout\" hidden></pre>\n";
    for sec in &p.sections {
        s += sec;
    }
    for (caption, png) in &p.figures {
        let _ = write!(
            s,
            "<figure><img alt=\"{c}\" src=\"data:image/png;base64,{}\"><figcaption>{c}</figcaption></figure>\n",
            base64(png),
            c = html(caption)
        );
    }
    if has_three() {
        let _ = write!(
            s,
            "<details class=\"licence\"><summary>three.js {} (MIT licence), embedded</summary><pre>{}</pre></details>\n",
            html(assets::THREE_VERSION.trim()),
            html(assets::THREE_LICENSE)
        );
    }
    let _ = write!(
        s,
        "<script type=\"application/json\" id=\"page-data\">{}</script>\n",
        json_script(&data)
    );
    if has_three() {
        s += &modules();
        let _ = write!(s, "<script>{}</script>\n", script(assets::BOOT_JS));
    }
    s += "</body></html>\n";
    Ok(s)
}
