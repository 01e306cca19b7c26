//! Rendering of typed reports: the figures (PNG and SVG, drawn with
//! plotters and typeset with the embedded DejaVu fonts), the report folders
//! of `--report DIR` (report.md, report.json, figures, and `index.html`,
//! the interactive 3D page of [`page`] assembled by [`pages`]), the frames file's
//! text and the paper's figures. The command line and the Python package
//! both call these; nothing here prints or names a flag.

pub mod bag_text;
pub mod bench_text;
pub mod bound_text;
pub mod camera_design;
pub mod camera_text;
pub mod contact_figures;
pub mod contact_sheet;
pub mod contact_text;
pub mod design_text;
pub(crate) mod figure;
pub mod fk_text;
pub mod folder;
pub mod frames_text;
pub mod measured_text;
pub mod page;
pub mod page_camera;
pub mod page_contacts;
pub mod pages;
pub mod paper_figures;
pub mod plots;
pub mod pool_text;
pub mod robot_text;
pub mod select_text;
pub mod simulated_text;
pub mod socket_design_text;
pub mod summary;
mod typeset;
