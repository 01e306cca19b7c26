use activecal::robot::{Robot, file};
use activecal::urdf::{self, UrdfOptions};
use std::path::Path;

#[test]
fn explore() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    for f in ["scara.toml", "ur5_pose.toml"] {
        match file::load(&dir.join(f)) {
            Ok(r) => println!("{f}: p={} minimal={} {}", r.n_unknowns(), r.minimal_unknowns(), r.parameter_names().join(" ")),
            Err(e) => println!("{f}: ERR {e}"),
        }
    }
    for f in ["ur5.urdf", "stanford.urdf"] {
        for m in [activecal::robot::Measurement::Point, activecal::robot::Measurement::Pose] {
            let o = UrdfOptions { measurement: m, ..Default::default() };
            match urdf::load(&dir.join(f), &o) {
                Ok(r) => {
                    println!("{f} {m:?}: p={} minimal={} {}", r.n_unknowns(), r.minimal_unknowns(), r.parameter_names().join(" "));
                    for (fr, row) in r.frames.iter().zip(&r.nominal.rows) { println!("   {} {:?} {:?} {:?}", fr.label, fr.convention, fr.joint, row); }
                }
                Err(e) => println!("{f}: ERR {e}"),
            }
        }
    }
    let puma = Robot::puma560();
    let text = urdf::to_urdf(&puma, &puma.nominal).unwrap();
    let r = urdf::parse(&text, "puma", &UrdfOptions::default()).unwrap();
    println!("puma urdf p={} {}", r.n_unknowns(), r.parameter_names().join(" "));
}
