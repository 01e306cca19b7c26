//! The collision geometry of a URDF's links: each element's shape (meshes
//! found through `package://` or beside the URDF), its placement on its link
//! and its bounding sphere.

use super::mesh;
use super::mesh_tree::MeshTree;
use super::spec::CollisionSpec;
use super::tree::{self, Tree};
use parry3d_f64::na::{Isometry3, Point3, Vector3};
use parry3d_f64::shape::{Ball, Capsule, Cuboid, Cylinder, SharedShape, TriMesh};
use std::path::{Path, PathBuf};

/// One collision geometry on a link.
pub(super) struct Geometry {
    pub(super) link: usize,
    /// Placement in the link frame.
    pub(super) origin: Isometry3<f64>,
    pub(super) shape: SharedShape,
    /// Bounding sphere in the geometry frame: centre and radius.
    pub(super) center: Point3<f64>,
    pub(super) radius: f64,
    /// A mesh's convex hull (in the geometry frame): it contains the mesh,
    /// so its distance bounds the mesh's from below at a fraction of the
    /// cost (`None` for primitive shapes, whose queries are cheap).
    pub(super) hull: Option<SharedShape>,
    /// A mesh's triangles in a box tree, for the mesh–mesh distances of
    /// move checks ([`mesh_tree::distance`]; `None` for primitive shapes).
    pub(super) tree: Option<MeshTree>,
}

/// Where a `package://PKG/rest` or relative mesh file is: the package
/// directories given, then the URDF's directory and its ancestors (a
/// directory named PKG, one holding PKG, or one whose `package.xml` names
/// PKG: a package checked out under another folder name).
pub(crate) fn resolve(file: &str, urdf_dir: &Path, package_dirs: &[String]) -> Option<PathBuf> {
    if let Some(rest) = file.strip_prefix("package://") {
        let (pkg, sub) = rest.split_once('/').unwrap_or((rest, ""));
        let mut roots: Vec<PathBuf> = package_dirs.iter().map(PathBuf::from).collect();
        roots.extend(urdf_dir.ancestors().map(Path::to_path_buf));
        for r in &roots {
            for cand in [r.join(pkg).join(sub), r.join(sub)] {
                let named = r.file_name().is_some_and(|n| n == pkg);
                if (named || cand.starts_with(r.join(pkg))) && cand.is_file() {
                    return Some(cand);
                }
            }
        }
        return urdf_dir
            .ancestors()
            .find(|r| package_name(r).as_deref() == Some(pkg))
            .map(|r| r.join(sub))
            .filter(|p| p.is_file());
    }
    let p = file.strip_prefix("file://").unwrap_or(file);
    let p = if Path::new(p).is_absolute() {
        PathBuf::from(p)
    } else {
        urdf_dir.join(p)
    };
    p.is_file().then_some(p)
}

/// The `<name>` of the ROS package whose `package.xml` is in `dir`, if any.
fn package_name(dir: &Path) -> Option<String> {
    let text = std::fs::read_to_string(dir.join("package.xml")).ok()?;
    let doc = roxmltree::Document::parse(&text).ok()?;
    doc.root_element()
        .children()
        .find(|n| n.has_tag_name("name"))
        .and_then(|n| n.text())
        .map(|t| t.trim().to_string())
}

/// The shape of a URDF collision element of `link`: a box, sphere,
/// cylinder, capsule, or a triangle mesh read from its file.
fn shape_of(
    g: &urdf_rs::Geometry,
    link: &str,
    urdf_dir: &Path,
    spec: &CollisionSpec,
) -> Result<SharedShape, String> {
    let positive = |what: &str, v: f64| -> Result<f64, String> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(format!(
                "link '{link}': collision {what} {v} must be finite and > 0"
            ))
        }
    };
    Ok(match g {
        urdf_rs::Geometry::Box { size } => SharedShape::new(Cuboid::new(Vector3::new(
            positive("box size", size[0])? / 2.0,
            positive("box size", size[1])? / 2.0,
            positive("box size", size[2])? / 2.0,
        ))),
        urdf_rs::Geometry::Sphere { radius } => {
            SharedShape::new(Ball::new(positive("sphere radius", *radius)?))
        }
        // URDF cylinders and capsules run along z, parry's along y: the
        // capsule is built along z, the cylinder turned by `along_z`.
        urdf_rs::Geometry::Cylinder { radius, length } => SharedShape::new(Cylinder::new(
            positive("cylinder length", *length)? / 2.0,
            positive("cylinder radius", *radius)?,
        )),
        urdf_rs::Geometry::Capsule { radius, length } => SharedShape::new(Capsule::new_z(
            positive("capsule length", *length)? / 2.0,
            positive("capsule radius", *radius)?,
        )),
        urdf_rs::Geometry::Mesh { filename, scale } => {
            let path = resolve(filename, urdf_dir, &spec.package_dirs).ok_or_else(|| {
                let holds = filename
                    .strip_prefix("package://")
                    .and_then(|r| r.split('/').next())
                    .map_or("it".to_string(), |pkg| format!("package '{pkg}'"));
                format!(
                    "link '{link}': mesh '{filename}' not found (searched {}the URDF's directory {} and its ancestors; name the package directory that holds {holds})",
                    spec.package_dirs.iter().map(|d| format!("{d}, ")).collect::<String>(),
                    if urdf_dir.as_os_str().is_empty() {
                        Path::new(".").display()
                    } else {
                        urdf_dir.display()
                    }
                )
            })?;
            let tris = mesh::load(&path).map_err(|e| format!("link '{link}': {e}"))?;
            let s = scale.as_ref().map_or([1.0; 3], |v| [v[0], v[1], v[2]]);
            let mut vertices = Vec::with_capacity(3 * tris.len());
            for t in &tris {
                for v in t {
                    vertices.push(Point3::new(v[0] * s[0], v[1] * s[1], v[2] * s[2]));
                }
            }
            let indices = (0..tris.len() as u32)
                .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
                .collect();
            SharedShape::new(
                TriMesh::new(vertices, indices).map_err(|e| {
                    format!("{}: not a usable triangle mesh: {e:?}", path.display())
                })?,
            )
        }
    })
}

/// The turn from a shape's own frame to the URDF element's: a URDF cylinder
/// runs along its z axis, parry's `Cylinder` along y, so it is turned by
/// +90° about x (y onto z); other shapes are built in the URDF's frame.
fn along_z(g: &urdf_rs::Geometry) -> Isometry3<f64> {
    match g {
        urdf_rs::Geometry::Cylinder { .. } => {
            Isometry3::rotation(Vector3::x() * std::f64::consts::FRAC_PI_2)
        }
        _ => Isometry3::identity(),
    }
}

/// Every collision element of every link, with its shape loaded (meshes
/// found beside the URDF or in the package directories) and its bounding
/// sphere.
pub(super) fn geometries(
    urdf: &urdf_rs::Robot,
    tree: &Tree,
    spec: &CollisionSpec,
) -> Result<Vec<Geometry>, String> {
    let urdf_dir = Path::new(&spec.urdf).parent().unwrap_or(Path::new("."));
    let mut geoms = Vec::new();
    for l in &urdf.links {
        let link = tree.index[&l.name];
        for c in &l.collision {
            let shape = shape_of(&c.geometry, &l.name, urdf_dir, spec)
                .map_err(|e| format!("{}: {e}", spec.urdf))?;
            let aabb = shape.compute_local_aabb();
            let center = aabb.center();
            let radius = aabb.half_extents().norm();
            let hull = shape
                .as_trimesh()
                .and_then(|m| SharedShape::convex_hull(m.vertices()));
            let tree = shape
                .as_trimesh()
                .map(|m| MeshTree::new(m.triangles().collect()));
            geoms.push(Geometry {
                link,
                origin: tree::pose(&c.origin) * along_z(&c.geometry),
                shape,
                center,
                radius,
                hull,
                tree,
            });
        }
    }
    Ok(geoms)
}

#[cfg(test)]
mod tests {
    use super::resolve;

    /// A scratch tree: `root/checkout/{package.xml, urdf/, meshes/a.stl}`,
    /// the package named `name` in its package.xml.
    fn tree(tag: &str, name: &str) -> std::path::PathBuf {
        let root =
            std::env::temp_dir().join(format!("activecal-resolve-{tag}-{}", std::process::id()));
        let pkg = root.join("checkout");
        std::fs::create_dir_all(pkg.join("urdf")).unwrap();
        std::fs::create_dir_all(pkg.join("meshes")).unwrap();
        std::fs::write(
            pkg.join("package.xml"),
            format!("<?xml version=\"1.0\"?>\n<package format=\"3\">\n  <name> {name} </name>\n  <version>1.0.0</version>\n</package>\n"),
        )
        .unwrap();
        std::fs::write(pkg.join("meshes/a.stl"), "solid a\nendsolid a\n").unwrap();
        root
    }

    #[test]
    fn a_package_is_found_by_the_name_its_package_xml_gives() {
        let root = tree("named", "my_robot_description");
        let urdf_dir = root.join("checkout/urdf");
        let found = resolve(
            "package://my_robot_description/meshes/a.stl",
            &urdf_dir,
            &[],
        );
        assert_eq!(found, Some(root.join("checkout/meshes/a.stl")));
        // Another package's name, or a file the package lacks: not found.
        assert_eq!(
            resolve("package://other/meshes/a.stl", &urdf_dir, &[]),
            None
        );
        assert_eq!(
            resolve(
                "package://my_robot_description/meshes/b.stl",
                &urdf_dir,
                &[]
            ),
            None
        );
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn a_folder_named_as_the_package_is_found_without_a_package_xml() {
        let root = tree("folder", "unrelated");
        let urdf_dir = root.join("checkout/urdf");
        assert_eq!(
            resolve("package://checkout/meshes/a.stl", &urdf_dir, &[]),
            Some(root.join("checkout/meshes/a.stl"))
        );
        std::fs::remove_dir_all(&root).unwrap();
    }
}
