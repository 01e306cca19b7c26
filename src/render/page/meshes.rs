//! The links' visual geometry for the page: each URDF `<visual>` as a box,
//! cylinder, sphere or mesh (STL, COLLADA, OBJ read by
//! [`crate::collision::mesh::load`], found as collision meshes are), meshes
//! welded into indexed triangle lists and, when the page would pass its
//! budget, decimated by vertex clustering (a grid whose cells each keep one
//! vertex, the mean of theirs; triangles that collapse are dropped) with the
//! cell size doubled until they fit.

use super::encode::base64;
use crate::collision::mesh;
use crate::collision::shapes::resolve;
use crate::collision::tree::pose;
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// Bytes of mesh data (before base64) a page may hold: with three.js
/// (2.1 MB) and the rest, a page stays under 10 MB.
pub const MESH_BUDGET_BYTES: usize = 5_000_000;

/// One visual element of a link.
#[derive(Clone, Debug, Serialize)]
pub struct Visual {
    /// Index of the link in the page's link list.
    pub link: usize,
    /// Placement on the link (column-major 4×4).
    pub origin: [f64; 16],
    /// The shape.
    #[serde(flatten)]
    pub shape: Shape,
    /// RGBA colour from the URDF's material, when it gives one.
    pub rgba: Option<[f64; 4]>,
}

/// A visual's shape (metres).
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Shape {
    /// A box of full sizes.
    Box {
        /// Full sizes along x, y, z.
        size: [f64; 3],
    },
    /// A cylinder along z.
    Cylinder {
        /// Radius.
        radius: f64,
        /// Length.
        length: f64,
    },
    /// A sphere.
    Sphere {
        /// Radius.
        radius: f64,
    },
    /// A mesh of the page's mesh list, scaled.
    Mesh {
        /// Index in the mesh list.
        mesh: usize,
        /// Scale per axis.
        scale: [f64; 3],
    },
}

/// A welded triangle mesh as the page embeds it.
#[derive(Clone, Debug, Serialize)]
pub struct MeshData {
    /// The URDF's file name of the mesh.
    pub file: String,
    /// Vertex coordinates, little-endian f32 xyz, base64.
    pub positions: String,
    /// Triangle vertex indices, little-endian u32, base64.
    pub indices: String,
    /// Triangles.
    pub triangles: usize,
    /// Triangles in the file.
    pub triangles_read: usize,
}

/// Indexed triangles: vertices and faces.
struct Welded {
    v: Vec<[f32; 3]>,
    f: Vec<[u32; 3]>,
    read: usize,
}

/// The visuals of a URDF's links (`links` the page's link names), the
/// meshes they name, and notes on what was not drawn or was decimated.
pub fn visuals(
    urdf: &urdf_rs::Robot,
    links: &[String],
    urdf_dir: &Path,
    package_dirs: &[String],
) -> (Vec<Visual>, Vec<MeshData>, Vec<String>) {
    let index: HashMap<&str, usize> = links
        .iter()
        .enumerate()
        .map(|(i, l)| (l.as_str(), i))
        .collect();
    let mut out = Vec::new();
    let mut files: BTreeMap<String, usize> = BTreeMap::new();
    let mut welded: Vec<(String, Welded)> = Vec::new();
    let mut notes = Vec::new();
    let mut missing: Vec<(String, String)> = Vec::new();
    for link in &urdf.links {
        let Some(&li) = index.get(link.name.as_str()) else {
            continue;
        };
        let before = missing.len();
        for v in &link.visual {
            let shape = match primitive(&v.geometry) {
                Some(s) => s,
                None => {
                    let urdf_rs::Geometry::Mesh { filename, scale } = &v.geometry else {
                        continue;
                    };
                    let k = match files.get(filename) {
                        Some(k) => *k,
                        None => match load(filename, urdf_dir, package_dirs) {
                            Ok(w) => {
                                files.insert(filename.clone(), welded.len());
                                welded.push((filename.clone(), w));
                                welded.len() - 1
                            }
                            Err(Missing::NotFound) => {
                                missing.push((link.name.clone(), filename.clone()));
                                continue;
                            }
                            Err(Missing::Unreadable(e)) => {
                                notes.push(format!("link '{}': {e}; not drawn", link.name));
                                continue;
                            }
                        },
                    };
                    let s = scale.as_ref().map_or([1.0; 3], |s| [s[0], s[1], s[2]]);
                    Shape::Mesh { mesh: k, scale: s }
                }
            };
            let rgba = v
                .material
                .as_ref()
                .and_then(|m| m.color.as_ref())
                .or_else(|| {
                    let name = v.material.as_ref()?.name.as_str();
                    urdf.materials
                        .iter()
                        .find(|m| m.name == name)?
                        .color
                        .as_ref()
                })
                .map(|c| [c.rgba[0], c.rgba[1], c.rgba[2], c.rgba[3]]);
            out.push(Visual {
                link: li,
                origin: super::column_major(&pose(&v.origin)),
                shape,
                rgba,
            });
        }
        if missing.len() > before {
            out.extend(stand_ins(link, li));
        }
    }
    if !missing.is_empty() {
        notes.push(missing_note(&missing));
    }
    let meshes = fit_budget(welded, MESH_BUDGET_BYTES, &mut notes);
    (out, meshes, notes)
}

/// A URDF geometry that is a primitive shape (a capsule drawn as its
/// cylinder); `None` for a mesh.
fn primitive(g: &urdf_rs::Geometry) -> Option<Shape> {
    Some(match g {
        urdf_rs::Geometry::Box { size } => Shape::Box {
            size: [size[0], size[1], size[2]],
        },
        urdf_rs::Geometry::Cylinder { radius, length }
        | urdf_rs::Geometry::Capsule { radius, length } => Shape::Cylinder {
            radius: *radius,
            length: *length,
        },
        urdf_rs::Geometry::Sphere { radius } => Shape::Sphere { radius: *radius },
        urdf_rs::Geometry::Mesh { .. } => return None,
    })
}

/// Grey, for a link's collision shapes drawn in place of its missing
/// visual meshes.
const STAND_IN_RGBA: [f64; 4] = [0.6, 0.6, 0.62, 1.0];

/// The collision boxes, cylinders and spheres of `link`, drawn in place of
/// its visual meshes when none of them was found.
fn stand_ins(link: &urdf_rs::Link, li: usize) -> Vec<Visual> {
    link.collision
        .iter()
        .filter_map(|c| {
            primitive(&c.geometry).map(|shape| Visual {
                link: li,
                origin: super::column_major(&pose(&c.origin)),
                shape,
                rgba: Some(STAND_IN_RGBA),
            })
        })
        .collect()
}

/// The page's note on the visual meshes not found (`(link, file)`): how
/// many, where they were looked for, and what is drawn instead.
fn missing_note(missing: &[(String, String)]) -> String {
    let links: std::collections::BTreeSet<&str> = missing.iter().map(|m| m.0.as_str()).collect();
    let files: std::collections::BTreeSet<&str> = missing.iter().map(|m| m.1.as_str()).collect();
    let first = files.iter().next().copied().unwrap_or_default();
    format!(
        "{} visual mesh file(s) of {} link(s) not found (such as {first}): a relative file is looked for beside the URDF, a package://PKG/… file in the package directories given, then in the URDF's folder and its ancestors (a folder named PKG, one holding it, or one whose package.xml names PKG); those links are drawn by their collision boxes, cylinders and spheres where they have them, and every link by the blue lines joining the link frames",
        files.len(),
        links.len()
    )
}

/// Why a mesh was not drawn.
enum Missing {
    /// Its file was not found.
    NotFound,
    /// Its file did not read.
    Unreadable(String),
}

/// Reads and welds a mesh file.
fn load(filename: &str, urdf_dir: &Path, package_dirs: &[String]) -> Result<Welded, Missing> {
    let path = resolve(filename, urdf_dir, package_dirs).ok_or(Missing::NotFound)?;
    let tris = mesh::load(&path).map_err(Missing::Unreadable)?;
    let read = tris.len();
    let pts: Vec<[f64; 3]> = tris.iter().flatten().copied().collect();
    Ok(cluster(&pts, 0.0, read))
}

/// Welds (cell 0: equal coordinates) or clusters (cell > 0 m) a triangle
/// soup `pts` (three points a triangle): one vertex per cell, the mean of
/// its points; triangles with two corners in one cell dropped.
fn cluster(pts: &[[f64; 3]], cell: f64, read: usize) -> Welded {
    let key = |p: &[f64; 3]| -> [i64; 3] {
        if cell > 0.0 {
            p.map(|c| (c / cell).floor() as i64)
        } else {
            p.map(|c| c.to_bits() as i64)
        }
    };
    let mut cells: HashMap<[i64; 3], u32> = HashMap::new();
    let mut sums: Vec<([f64; 3], f64)> = Vec::new();
    let mut f = Vec::with_capacity(pts.len() / 3);
    for t in pts.chunks_exact(3) {
        let mut tri = [0u32; 3];
        for (c, p) in tri.iter_mut().zip(t) {
            let id = *cells.entry(key(p)).or_insert_with(|| {
                sums.push(([0.0; 3], 0.0));
                (sums.len() - 1) as u32
            });
            let s = &mut sums[id as usize];
            (0..3).for_each(|i| s.0[i] += p[i]);
            s.1 += 1.0;
            *c = id;
        }
        if tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2] {
            f.push(tri);
        }
    }
    let v = sums
        .iter()
        .map(|(s, n)| [(s[0] / n) as f32, (s[1] / n) as f32, (s[2] / n) as f32])
        .collect();
    Welded { v, f, read }
}

/// Bytes a welded mesh takes in the page.
fn bytes(w: &Welded) -> usize {
    12 * w.v.len() + 12 * w.f.len()
}

/// The meshes, decimated together (one cell size for all, from 1 mm,
/// doubled) until they fit `budget` bytes; a note says so.
fn fit_budget(
    welded: Vec<(String, Welded)>,
    budget: usize,
    notes: &mut Vec<String>,
) -> Vec<MeshData> {
    let total = |ws: &[(String, Welded)]| ws.iter().map(|(_, w)| bytes(w)).sum::<usize>();
    let mut ws = welded;
    let before = total(&ws);
    let mut cell = 0.001;
    while total(&ws) > budget && cell < 1.0 {
        ws = ws
            .into_iter()
            .map(|(name, w)| {
                let pts: Vec<[f64; 3]> =
                    w.f.iter()
                        .flat_map(|t| t.map(|i| w.v[i as usize].map(f64::from)))
                        .collect();
                let c = cluster(&pts, cell, w.read);
                (name, c)
            })
            .collect();
        cell *= 2.0;
    }
    if total(&ws) < before {
        notes.push(format!(
            "meshes decimated to fit the page: {} triangles of {} read ({:.1} MB of mesh data of {:.1} MB), vertices merged on a {:.0} mm grid",
            ws.iter().map(|(_, w)| w.f.len()).sum::<usize>(),
            ws.iter().map(|(_, w)| w.read).sum::<usize>(),
            total(&ws) as f64 / 1e6,
            before as f64 / 1e6,
            cell / 2.0 * 1e3
        ));
    }
    ws.into_iter()
        .map(|(file, w)| MeshData {
            file,
            positions: base64(
                &w.v.iter()
                    .flatten()
                    .flat_map(|x| x.to_le_bytes())
                    .collect::<Vec<u8>>(),
            ),
            indices: base64(
                &w.f.iter()
                    .flatten()
                    .flat_map(|x| x.to_le_bytes())
                    .collect::<Vec<u8>>(),
            ),
            triangles: w.f.len(),
            triangles_read: w.read,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat square of side 1 m cut into `n × n` cells of two triangles.
    fn square(n: usize) -> Vec<[f64; 3]> {
        let h = 1.0 / n as f64;
        let mut pts = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (i as f64 * h, j as f64 * h);
                pts.extend([[x, y, 0.0], [x + h, y, 0.0], [x + h, y + h, 0.0]]);
                pts.extend([[x, y, 0.0], [x + h, y + h, 0.0], [x, y + h, 0.0]]);
            }
        }
        pts
    }

    #[test]
    fn welding_shares_vertices_and_keeps_every_triangle() {
        // h = 1/8 is exact in binary: shared corners have equal bits.
        let w = cluster(&square(8), 0.0, 128);
        assert_eq!(w.f.len(), 128);
        assert_eq!(w.v.len(), 81);
    }

    #[test]
    fn decimation_fits_the_budget_and_says_so() {
        let w = cluster(&square(256), 0.0, 131_072);
        let before = bytes(&w);
        let mut notes = Vec::new();
        let out = fit_budget(vec![("sq".into(), w)], before / 10, &mut notes);
        let kept = out[0].triangles;
        assert!(12 * kept < before / 10, "{kept} triangles kept");
        assert!(kept > 100, "{kept} triangles kept");
        assert_eq!(out[0].triangles_read, 131_072);
        assert!(notes[0].contains("decimated"), "{notes:?}");
    }
}
