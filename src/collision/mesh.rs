//! Collision mesh files by format: STL (this crate's own reader, [`stl`]),
//! COLLADA (`.dae`) and Wavefront OBJ (openrr's `mesh-loader`). A COLLADA
//! file's `<unit meter>` is applied by the loader; its `<up_axis>` is read
//! (an unknown value is an error) but not applied: the URDF world takes a
//! mesh's coordinates as written, as Pinocchio (Coal through Assimp, with
//! COLLADA's up direction ignored) does. Checked on the TIAGo's
//! `arm_3_collision.dae`, tagged `Y_UP`: Coal's bounding box of the loaded
//! mesh equals the file's vertices', and only without a turn do activecal's
//! verdicts agree with Coal's (`verify/tests/live_collision.rs`). A `.dae`
//! file that is not COLLADA (no `<COLLADA>` root element) is refused by name.

use super::stl::{self, Triangles};
use std::path::Path;

/// The triangles of the mesh file at `path` (metres, z up), by extension.
pub fn load(path: &Path) -> Result<Triangles, String> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| format!("{name}: {e}"))?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "stl" => stl::parse(&bytes, &name),
        "dae" => collada(&bytes, &name),
        "obj" => {
            let scene = mesh_loader::obj::from_slice(&bytes, Some(path), |_| {
                // Materials do not matter for collision.
                Err::<Vec<u8>, _>(std::io::Error::other("materials are not read"))
            })
            .map_err(|e| format!("{name}: not a readable OBJ file: {e}"))?;
            triangles(&scene, &name)
        }
        _ => Err(format!(
            "{name}: collision meshes are read from STL, COLLADA (.dae) or OBJ files"
        )),
    }
}

/// A COLLADA document's triangles, as written (its up axis not applied).
fn collada(bytes: &[u8], name: &str) -> Result<Triangles, String> {
    let text = std::str::from_utf8(bytes)
        .map_err(|_| format!("{name}: not a COLLADA file (not UTF-8 XML text)"))?;
    let doc = roxmltree::Document::parse(text)
        .map_err(|e| format!("{name}: not a COLLADA file (not XML: {e})"))?;
    let root = doc.root_element();
    if root.tag_name().name() != "COLLADA" {
        return Err(format!(
            "{name}: not a COLLADA file (its root element is <{}>, not <COLLADA>)",
            root.tag_name().name()
        ));
    }
    let up = root
        .children()
        .find(|n| n.tag_name().name() == "asset")
        .and_then(|a| a.children().find(|n| n.tag_name().name() == "up_axis"))
        .and_then(|n| n.text())
        .map_or("Z_UP".to_string(), |t| t.trim().to_string());
    if !matches!(up.as_str(), "X_UP" | "Y_UP" | "Z_UP") {
        return Err(format!("{name}: unknown COLLADA <up_axis> '{up}'"));
    }
    let scene = mesh_loader::collada::from_str(text)
        .map_err(|e| format!("{name}: not a readable COLLADA file: {e}"))?;
    triangles(&scene, name)
}

/// Every face of every mesh of `scene` as a triangle; a face naming a vertex the mesh lacks, a non-finite vertex or
/// an empty scene is an error naming the file.
fn triangles(scene: &mesh_loader::Scene, name: &str) -> Result<Triangles, String> {
    let mut out: Triangles = Vec::new();
    for m in &scene.meshes {
        for f in &m.faces {
            let mut t = [[0.0; 3]; 3];
            for (k, &i) in f.iter().enumerate() {
                let v = m.vertices.get(i as usize).ok_or_else(|| {
                    format!(
                        "{name}: mesh '{}' names vertex {i} of {}",
                        m.name,
                        m.vertices.len()
                    )
                })?;
                let v = [f64::from(v[0]), f64::from(v[1]), f64::from(v[2])];
                if v.iter().any(|c| !c.is_finite()) {
                    return Err(format!(
                        "{name}: mesh '{}' has a vertex that is not finite",
                        m.name
                    ));
                }
                t[k] = v;
            }
            out.push(t);
        }
    }
    if out.is_empty() {
        return Err(format!("{name}: no triangles"));
    }
    Ok(out)
}
