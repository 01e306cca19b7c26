//! verify's tests in one binary (one compile and one link for all): the
//! fixture checks that plain `cargo test` runs, and, with feature `live`,
//! the checks against Pinocchio, MuJoCo and Coal, which share one embedded
//! interpreter. Each file is a module; the root crate's
//! `every_test_file_is_a_module` fails while a file is not listed here. Run
//! one file's tests with `cargo test -p verify --features live --test all FILE::`.

mod model;

#[cfg(feature = "live")]
mod live;
#[cfg(feature = "live")]
mod live_bag_calibrate;
#[cfg(feature = "live")]
mod live_bag_images;
#[cfg(feature = "live")]
mod live_bags;
#[cfg(feature = "live")]
mod live_bound;
#[cfg(feature = "live")]
mod live_camera;
#[cfg(feature = "live")]
mod live_camera_head;
#[cfg(feature = "live")]
mod live_camera_sight;
#[cfg(feature = "live")]
mod live_camera_truth;
#[cfg(feature = "live")]
mod live_collision;
#[cfg(feature = "live")]
mod live_contacts;
#[cfg(feature = "live")]
mod live_erd;
#[cfg(feature = "live")]
mod live_export;
#[cfg(feature = "live")]
mod live_fisheye;
#[cfg(feature = "live")]
mod live_gravity;
#[cfg(feature = "live")]
mod live_idjac;
#[cfg(feature = "live")]
mod live_images;
#[cfg(feature = "live")]
mod live_images_truth;
#[cfg(feature = "live")]
mod live_messy;
#[cfg(feature = "live")]
mod live_messy_camera;
#[cfg(feature = "live")]
mod live_messy_contact;
#[cfg(feature = "live")]
mod live_stack;
#[cfg(feature = "live")]
mod live_tour;
#[cfg(feature = "live")]
mod live_truth;
