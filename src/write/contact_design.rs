//! The configurations chosen for sockets
//! ([`crate::select::contact::socket_design::SocketDesign`]) in the
//! formats a design is written in, told apart by the extension
//! ([`crate::io::design_formats::DesignFormat`]):
//!
//! * `.json`: the whole design with its figures;
//! * `.csv`: a contact file to fill in: a `point` column, the joint names
//!   and `id`, one configuration a row (what `calibrate --measurements`
//!   reads once recorded);
//! * `.yaml`: the figures and the configurations as named joint
//!   configurations, `configurations: [{name: pose_01, id: 17, point:
//!   front_left/0, joints: {joint_a: 0.1, ...}}]` (as a design's YAML).

use crate::error::{Error, Result};
use crate::io::design_formats::Joints;
use crate::select::contact::socket_design::SocketDesign;
use serde::Serialize;

/// The design as pretty JSON.
#[must_use]
pub fn to_json(d: &SocketDesign) -> String {
    serde_json::to_string_pretty(d).expect("a socket design serializes") + "\n"
}

/// The design as a contact file to fill in (CSV).
#[must_use]
pub fn to_csv(d: &SocketDesign) -> String {
    let mut s = format!("point,{},id\n", d.joint_names.join(","));
    for c in &d.configurations {
        s += &c.point;
        for v in &c.q {
            s += &format!(",{v:?}");
        }
        s += &format!(",{}\n", c.id);
    }
    s
}

/// One named joint configuration of the YAML form.
#[derive(Serialize)]
struct Named<'a> {
    name: String,
    id: usize,
    point: &'a str,
    reach_m: f64,
    joints: Joints<'a>,
}

/// The design without its configurations, then the named ones.
#[derive(Serialize)]
struct Doc<'a> {
    #[serde(flatten)]
    design: serde_json::Value,
    configurations: Vec<Named<'a>>,
}

/// The design as YAML (see the module docs).
pub fn to_yaml(d: &SocketDesign) -> Result<String> {
    let width = d.configurations.len().to_string().len().max(2);
    let configurations: Vec<Named<'_>> = d
        .configurations
        .iter()
        .enumerate()
        .map(|(k, c)| Named {
            name: format!("pose_{:0width$}", k + 1),
            id: c.id,
            point: &c.point,
            reach_m: c.reach_m,
            joints: Joints {
                names: &d.joint_names,
                q: &c.q,
            },
        })
        .collect();
    let mut design = serde_json::to_value(d).expect("a socket design serializes");
    if let Some(m) = design.as_object_mut() {
        m.remove("configurations");
    }
    serde_saphyr::to_string(&Doc {
        design,
        configurations,
    })
    .map_err(|e| Error::Invalid(format!("writing YAML: {e}")))
}
