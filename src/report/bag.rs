//! What a calibration's report says of its ROS 2 bag
//! ([`crate::experiment::bag`]): the extraction and how the clock offset
//! was settled.

use crate::io::bag::clock::Offset;
use crate::io::bag::extract::ExtractReport;
use serde::Serialize;

/// How a calibration from a bag settled the clock offset: the estimate from
/// the nominal model's predicted moves, the calibrated model's, and
/// whether the data were extracted and fitted again with the latter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClockRefit {
    /// The estimate with the nominal model (s, with its uncertainty).
    pub nominal: Offset,
    /// The estimate with the calibrated model, when made (the first fit
    /// converged and enough moves were seen).
    pub calibrated: Option<Offset>,
    /// Whether the calibrated model's estimate moved by more than the
    /// nominal one's uncertainty, so that the bag was extracted and the
    /// robot fitted once more with it.
    pub refitted: bool,
}

/// What a calibration's report says of its bag: the extraction and, when
/// the clock offset was estimated, both estimates.
#[derive(Clone, Debug, Serialize)]
pub struct BagSection {
    /// The extraction that gave the measurements.
    pub extraction: ExtractReport,
    /// The clock offset estimated twice, when it was estimated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clock_refit: Option<ClockRefit>,
}
