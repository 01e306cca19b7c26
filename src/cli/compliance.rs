//! `calibrate --compliance`, `--inertia`, `--payload` and
//! `--compare-compliance`: the options parsed into a gravity model, and the
//! rendering of compliances and of the side-by-side held-out comparison.
//! The work is in `activecal::identify::compliance`.

use activecal::identify::compliance::ComplianceComparison;
use activecal::identify::compliance::ComplianceReport;
use activecal::io::inertia::{InertiaOptions, Payload, gravity_model};
use activecal::model::Robot;
use activecal::model::gravity::GravityModel;
use anyhow::{Context, Result, bail};
use std::path::Path;
use std::sync::Arc;

/// Parses `--payload KG[@X,Y,Z]` (kg; metres in the tip link's frame).
pub fn parse_payload(s: &str) -> Result<Payload, String> {
    let (m, at) = match s.split_once('@') {
        Some((m, at)) => (m, Some(at)),
        None => (s, None),
    };
    let mass: f64 = m
        .trim()
        .parse()
        .map_err(|_| format!("'{m}' is not a mass in kg (KG or KG@X,Y,Z)"))?;
    if !(mass.is_finite() && mass >= 0.0) {
        return Err(format!("{mass} kg: the mass must be finite and >= 0"));
    }
    let at = match at {
        None => [0.0; 3],
        Some(a) => {
            let v: Vec<f64> = a
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| format!("'{a}' is not X,Y,Z in metres"))?;
            if v.len() != 3 || !v.iter().all(|x| x.is_finite()) {
                return Err(format!("'{a}' is not three finite numbers X,Y,Z (metres)"));
            }
            [v[0], v[1], v[2]]
        }
    };
    Ok(Payload { mass, at })
}

/// The gravity model of `robot` from its URDF's inertials, or from
/// `inertia`'s (another URDF with the same link names), with `payload`.
pub fn gravity_for(
    robot: &Robot,
    inertia: Option<&Path>,
    payload: Option<Payload>,
) -> Result<Arc<GravityModel>> {
    let inertials = match inertia {
        Some(p) => Some((
            std::fs::read_to_string(p).with_context(|| format!("--inertia {}", p.display()))?,
            p.display().to_string(),
        )),
        None => None,
    };
    if robot.source.is_none() {
        bail!(
            "--compliance needs a URDF robot (gravity torques come from its <inertial> elements); '{}' is not one",
            robot.name
        );
    }
    let opts = InertiaOptions { inertials, payload };
    Ok(Arc::new(gravity_model(robot, &opts)?))
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

fn join(v: &[f64], d: usize) -> String {
    v.iter()
        .map(|x| format!("{x:.d$}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The text of a comparison.
#[must_use]
pub fn comparison_text(c: &ComplianceComparison) -> String {
    let mut s = format!(
        "geometric only:   held-out position RMS {:.3} mm (per split {}), fitted {:.3} mm\n",
        mean(&c.geometric_position_rms_mm),
        join(&c.geometric_position_rms_mm, 3),
        mean(&c.geometric_fitted_rms_mm)
    );
    s += &format!(
        "with compliance:  held-out position RMS {:.3} mm (per split {}), fitted {:.3} mm\n",
        mean(&c.compliant_position_rms_mm),
        join(&c.compliant_position_rms_mm, 3),
        mean(&c.compliant_fitted_rms_mm)
    );
    if let (Some(g), Some(k)) = (
        &c.geometric_orientation_rms_deg,
        &c.compliant_orientation_rms_deg,
    ) {
        s += &format!(
            "held-out orientation RMS {:.4}° geometric, {:.4}° with compliance\n",
            mean(g),
            mean(k)
        );
    }
    s + &format!("  → {}\n", c.verdict)
}

/// The text of fitted compliances.
#[must_use]
pub fn compliance_text(r: &ComplianceReport) -> String {
    let mut s = format!(
        "\n{:<22} {:>12} {:>11} {:>7} {:>14} {:>18} {:>10} {:>9}\n",
        "compliance", "c rad/(N·m)", "σ", "t", "k N·m/rad", "τ range N·m", "max mrad", "max mm"
    );
    for e in &r.estimates {
        s += &format!(
            "{:<22} {:>12.4e} {:>11} {:>7} {:>14} {:>18} {:>10.3} {:>9.3}\n",
            e.joint,
            e.c,
            e.std.map_or("-".into(), |v| format!("{v:.3e}")),
            e.t.map_or("-".into(), |v| format!("{v:.2}")),
            e.stiffness_nm_per_rad
                .map_or("-".into(), |k| format!("{k:.4e}")),
            format!("{:.2} … {:.2}", e.torque_range_nm[0], e.torque_range_nm[1]),
            e.max_deflection_mrad,
            e.max_deflection_tool_mm
        );
    }
    for w in &r.without {
        s += &format!("{:<22} no compliance: {}\n", w.joint, w.reason);
    }
    s + &format!(
        "largest deflection of the end point over the data: {:.3} mm\n",
        r.max_tool_deflection_mm
    )
}
