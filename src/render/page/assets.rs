//! What the page embeds: three.js (copied from `web/node_modules/three` by
//! `build.rs`; empty when it was not installed) with its licence, and the
//! page's own script and style (`web/src/`).

/// three.js's core module.
pub const THREE_CORE: &str = include_str!(concat!(env!("OUT_DIR"), "/three.core.js"));
/// three.js's module (imports the core as `./three.core.js`).
pub const THREE_MODULE: &str = include_str!(concat!(env!("OUT_DIR"), "/three.module.js"));
/// three.js's orbit controls (imports `three`).
pub const ORBIT_CONTROLS: &str = include_str!(concat!(env!("OUT_DIR"), "/OrbitControls.js"));
/// three.js's licence (MIT).
pub const THREE_LICENSE: &str = include_str!(concat!(env!("OUT_DIR"), "/three.LICENSE"));
/// The three.js version embedded.
pub const THREE_VERSION: &str = include_str!(concat!(env!("OUT_DIR"), "/three.version"));
/// The page's own module (imports `three` and
/// `three/addons/controls/OrbitControls.js`).
pub const PAGE_JS: &str = include_str!("../../../web/src/page.js");
/// The page's style sheet.
pub const PAGE_CSS: &str = include_str!("../../../web/src/page.css");
/// The loader: turns the embedded modules into blob URLs (a page opened
/// from `file://` can import nothing else) and imports the page's module.
pub const BOOT_JS: &str = include_str!("../../../web/src/boot.js");

/// Whether three.js was embedded at build time.
#[must_use]
pub fn has_three() -> bool {
    cfg!(activecal_three) && !THREE_CORE.is_empty()
}
