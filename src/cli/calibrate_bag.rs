//! `calibrate --bag`: a fit of the measurements a ROS 2 bag gives
//! ([`activecal::experiment::bag::calibrate_bag`] does the work: the
//! extraction, the fit, the clock offset estimated again with the
//! calibrated model); here the options are read and the fit rendered as a
//! measurement file's is.

use super::calibrate::{CalibrateArgs, Source, measured_settings, render_measured, scaled_robot};
use activecal::model::Robot;
use anyhow::{Context, Result};
use std::time::Instant;

/// The joint topic when `--joints` is not given.
const DEFAULT_JOINTS: &str = "/joint_states";

/// Calibrates `robot` from `--bag`.
pub fn from_bag(a: &CalibrateArgs, robot: &Robot) -> Result<()> {
    let t0 = Instant::now();
    let bag = a.bag.as_deref().context("--bag: not given")?;
    let robot = &scaled_robot(a, robot)?;
    let o = measured_settings(a, robot)?;
    let joints = a
        .joints
        .as_deref()
        .map_or(DEFAULT_JOINTS.into(), |j| j.to_string_lossy());
    let mut x = a.from_bag.settings(&joints, a.design_tolerance)?;
    if let Some(d) = &a.bag_design {
        x.design = Some(activecal::io::bag::design::read_design(d, robot)?);
    }
    let mut print_note = |n: &str| {
        if !a.json {
            super::diag(&format!("note: {n}"));
        }
    };
    let got = activecal::experiment::bag::calibrate_bag(bag, robot, &x, &o, &mut print_note)?;
    let mut json = serde_json::json!({ "extraction": got.extraction });
    if let Some(c) = &got.clock {
        json["clock_refit"] = serde_json::to_value(c)?;
    }
    let mut text = super::extract::text(&got.extraction, None);
    if let Some(c) = &got.clock {
        text += &format!("{}\n", activecal::experiment::bag::clock_note(c));
    }
    text += "\n";
    let source = Source {
        name: bag.display().to_string(),
        described: format!("ROS 2 bag `{}`", bag.display()),
        json: Some(("bag", json)),
        text,
    };
    render_measured(a, robot, &got.measurements, got.calibration, &o, &source, t0)
}
