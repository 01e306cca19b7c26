//! `fk`'s text: the end point, its orientation, the markers and the
//! identification Jacobian's columns.

use crate::report::FkReport;

/// `fk`'s report as text: the position (12 decimals), the orientation
/// (roll, pitch, yaw and the quaternion) when the sensor observes it, each
/// marker, and one line per parameter with its Jacobian column.
#[must_use]
pub fn text(r: &FkReport) -> String {
    let [x, y, z] = r.position;
    let mut s = format!("position: {x:.12} {y:.12} {z:.12}\n");
    if let Some(o) = &r.orientation {
        let [ro, pi, ya] = o.rpy;
        let [w, qx, qy, qz] = o.quaternion;
        s += &format!(
            "orientation rpy (rad, R = Rz·Ry·Rx): {ro:.12} {pi:.12} {ya:.12}\nquaternion (w x y z): {w:.12} {qx:.12} {qy:.12} {qz:.12}\n"
        );
    }
    for (k, m) in r.markers.iter().flatten().enumerate() {
        s += &format!("marker {}: {:.12} {:.12} {:.12}\n", k + 1, m[0], m[1], m[2]);
    }
    if let (Some(jac), Some(names)) = (&r.jacobian, &r.parameter_names) {
        for (c, name) in names.iter().enumerate() {
            s += &format!("{name:>8}:");
            for row in jac {
                s += &format!(" {:>14.8}", row[c]);
            }
            s += "\n";
        }
    }
    s
}
