//! What a sensor measures at a pose: the region it sees ([`visibility`]) and
//! the rotation maps of full-pose measurements ([`so3`]).

pub mod so3;
pub mod visibility;

pub use visibility::Visibility;
