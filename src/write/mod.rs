//! Results written to files, each in the format its file name asks for:
//! a calibrated robot ([`calibrated`]: URDF, frames file, TOML description,
//! driver files), the frames file's text ([`frames`]), a contact design
//! ([`contact_design`]), a robot as it is ([`robot`]) and a pool's poses
//! ([`poses`]). Above the algorithms whose results they write and
//! above [`crate::io`], whose readers and atomic writing they use; the
//! command line and the Python package both call these.

pub mod calibrated;
pub mod contact_design;
pub mod frames;
pub mod poses;
pub mod robot;
