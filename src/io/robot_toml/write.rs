//! A robot written back as a description file that reads back to the same
//! robot.

use crate::measure::Visibility;
use crate::model::{Convention, JointKind, Robot, Symbol};
use serde::Serialize;

/// Writes a robot as a description that [`super::parse`] reads back to the same
/// robot (tables bit for bit: numbers are written as the shortest decimals
/// that round-trip; limits in radians or metres). A DH frame's β is written
/// when finite (the paper's marker 10), omitted otherwise.
#[must_use]
pub fn to_toml(robot: &Robot) -> String {
    description_to_toml(robot, None)
}

/// As [`to_toml`], with a visibility region.
#[must_use]
pub fn description_to_toml(robot: &Robot, visibility: Option<&Visibility>) -> String {
    let num = |x: f64| format!("{x:?}");
    let list = |r: &[f64]| {
        let v: Vec<String> = r.iter().map(|&x| num(x)).collect();
        format!("[{}]", v.join(", "))
    };
    let mut s = String::new();
    s += "# activecal robot description (see activecal::io::robot_toml)\n";
    s += &format!("name = {:?}\n", robot.name);
    s += &format!("measurement = \"{}\"\n", robot.measurement.name());
    // The orientation scale weighs orientation rows: written for a sensor
    // that has them.
    if crate::measure::sensor_for(robot)
        .row_kinds()
        .contains(&crate::measure::RowKind::Orientation)
    {
        s += &format!("orientation_scale = {}\n", num(robot.orientation_scale));
    }
    for (n, r) in robot.nominal.markers.iter().zip(&robot.real.markers) {
        s += &format!("\n[[marker]]\nnominal = {}\nreal = {}\n", list(n), list(r));
    }
    for (i, f) in robot.frames.iter().enumerate() {
        s += "\n[[frame]]\n";
        s += &format!("label = {:?}\n", f.label);
        s += &format!(
            "convention = \"{}\"\n",
            match f.convention {
                Convention::Dh => "dh",
                Convention::Hayati => "hayati",
            }
        );
        let joint = match (f.joint, f.joint_kind) {
            (None, _) => "fixed",
            (Some(_), JointKind::Revolute) => "revolute",
            (Some(_), JointKind::Prismatic) => "prismatic",
        };
        s += &format!("joint = \"{joint}\"\n");
        if let Some(j) = f.joint {
            s += &format!("limits = {}\n", list(&robot.limits[j]));
        }
        for (name, t) in [("real", &robot.real), ("nominal", &robot.nominal)] {
            let r = &t.rows[i];
            let n = if f.convention == Convention::Dh && !r[4].is_finite() {
                4
            } else {
                5
            };
            s += &format!("{name} = {}\n", list(&r[..n]));
        }
        let syms: Vec<String> = robot
            .unknowns
            .iter()
            // A compliance belongs to the gravity model, not the description.
            .filter(|u| u.frame == i && u.symbol != Symbol::C)
            .map(|u| format!("\"{}\"", u.symbol))
            .collect();
        if !syms.is_empty() {
            s += &format!("unknowns = [{}]\n", syms.join(", "));
        }
    }
    if let Some(v) = visibility {
        #[derive(Serialize)]
        struct W<'a> {
            visibility: &'a Visibility,
        }
        if let Ok(t) = toml::to_string(&W { visibility: v }) {
            s += "\n";
            s += &t;
        }
    }
    s
}
