//! Collision meshes in COLLADA and OBJ load as STL does: a COLLADA file's
//! unit and up axis are honoured, and a `.dae` that is not COLLADA is
//! refused by name.

use activecal::collision::mesh;

/// A COLLADA file with one triangle (0,0,0), (10,0,0), (0,20,0) in the
/// given unit and up axis.
fn dae(meter: &str, up: &str) -> String {
    format!(
        r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="u" meter="{meter}"/><up_axis>{up}</up_axis></asset>
  <library_geometries>
    <geometry id="g" name="g"><mesh>
      <source id="p"><float_array id="pa" count="9">0 0 0 10 0 0 0 20 0</float_array>
        <technique_common><accessor source="#pa" count="3" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
      <triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n">
    <instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>"##
    )
}

fn write(name: &str, text: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("activecal-mesh-formats-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn max_abs(t: &[[[f64; 3]; 3]], axis: usize) -> f64 {
    t.iter()
        .flatten()
        .map(|v| v[axis].abs())
        .fold(0.0, f64::max)
}

#[test]
fn collada_units_are_honoured_and_the_up_axis_is_not_applied() {
    // Millimetres, z up: 10 mm along x, 20 mm along y.
    let z = mesh::load(&write("z.dae", &dae("0.001", "Z_UP"))).unwrap();
    assert_eq!(z.len(), 1);
    // f32 vertices scaled by 0.001: relative 6e-8 of 0.02 m is 1.2e-9 m;
    // 1e-8 m.
    assert!((max_abs(&z, 0) - 0.010).abs() < 1e-8);
    assert!((max_abs(&z, 1) - 0.020).abs() < 1e-8);
    assert!(max_abs(&z, 2) < 1e-12);
    // Y up: the coordinates stay as written (the file's y, 20 mm, stays y),
    // as Pinocchio and Coal load it (verify/tests/live_collision.rs).
    let y = mesh::load(&write("y.dae", &dae("0.001", "Y_UP"))).unwrap();
    assert!((max_abs(&y, 1) - 0.020).abs() < 1e-8);
    assert!(max_abs(&y, 2) < 1e-12);
    // Metres: no scaling.
    let m = mesh::load(&write("m.dae", &dae("1", "Z_UP"))).unwrap();
    assert!((max_abs(&m, 1) - 20.0).abs() < 1e-8);
}

#[test]
fn obj_meshes_load() {
    let p = write(
        "t.obj",
        "v 0 0 0\nv 1 0 0\nv 0 2 0\nv 0 0 3\nf 1 2 3\nf 1 2 4\n",
    );
    let t = mesh::load(&p).unwrap();
    assert_eq!(t.len(), 2);
    assert!((max_abs(&t, 2) - 3.0).abs() < 1e-12);
}

#[test]
fn a_dae_that_is_not_collada_is_refused_by_name() {
    let p = write("bad.dae", "solid x\nendsolid x\n");
    let e = mesh::load(&p).unwrap_err();
    assert!(
        e.contains("bad.dae") && e.contains("not a COLLADA file"),
        "{e}"
    );
    let p = write("other.dae", "<?xml version=\"1.0\"?><svg/>");
    let e = mesh::load(&p).unwrap_err();
    assert!(
        e.contains("<svg>") && e.contains("not a COLLADA file"),
        "{e}"
    );
    let p = write("x.ply", "ply\n");
    assert!(
        mesh::load(&p)
            .unwrap_err()
            .contains("STL, COLLADA (.dae) or OBJ")
    );
}
