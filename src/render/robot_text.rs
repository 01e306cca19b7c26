//! The text of a robot described (`robots`): chain, joints with limits,
//! parameter tables (lengths in metres, angles in radians), unknowns.

use crate::model::Robot;

/// The largest made-up error of a URDF robot's "real" parameters (metres
/// or radians, [`crate::model::catalogue::perturbation`]).
const URDF_REAL_MAX: f64 = 5e-3;

/// One robot of `robots`' text: chain, joints with limits, parameter
/// tables (lengths in metres, angles in radians), unknowns.
#[must_use]
pub fn text(r: &Robot) -> String {
    let mut s = format!(
        "{} ({} joints, {} unknowns)\nchain: {}\n",
        r.name,
        r.dof(),
        r.n_unknowns(),
        crate::report::chain(r).join(" -> ")
    );
    s += "joint                            kind        lower       upper\n";
    for ((name, k), l) in crate::units::joint_names(r)
        .iter()
        .zip(crate::report::joint_kinds(r))
        .zip(&r.limits)
    {
        let (lo, hi, unit) = match k {
            crate::model::JointKind::Revolute => (l[0].to_degrees(), l[1].to_degrees(), "deg"),
            crate::model::JointKind::Prismatic => (l[0], l[1], "m"),
        };
        s += &format!(
            "{name:<32} {:<10} {lo:>9.3} {hi:>9.3} {unit}\n",
            format!("{k:?}").to_lowercase()
        );
    }
    let w = r
        .frames
        .iter()
        .map(|f| f.label.chars().count())
        .max()
        .unwrap_or(5)
        .max(5);
    if r.source.is_some() {
        // A URDF has no measured values: say what the "real" rows are.
        s += &format!(
            "real: not your robot — the URDF's values with a made-up error of at most {:.0} mm or {:.0} mrad on each unknown: the robot `calibrate --design` simulates measuring (--params real)\n",
            URDF_REAL_MAX * 1e3,
            URDF_REAL_MAX * 1e3
        );
    }
    s += &format!(
        "{:>w$}  conv    joint   gamma(rad)  alpha(rad)        a(m)        d(m)   beta(rad)   (real | nominal)\n",
        "frame"
    );
    for (i, f) in r.frames.iter().enumerate() {
        for (tag, t) in [("real", &r.real), ("nom ", &r.nominal)] {
            let row = t.rows[i];
            s += &format!(
                "{:>w$}  {:<6}  {:>5} {tag} {:>10.4}  {:>10.4}  {:>10.4}  {:>10.4}  {:>10.4}\n",
                f.label,
                format!("{:?}", f.convention),
                f.joint.map_or("-".into(), |j| format!("q{}", j + 1)),
                row[0],
                row[1],
                row[2],
                row[3],
                row[4]
            );
        }
    }
    s + &format!("unknowns: {}\n", r.parameter_names().join(" "))
}
