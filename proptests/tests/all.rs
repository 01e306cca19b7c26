//! The property tests in one binary (one compile and one link for all).
//! Each file is a module; the root crate's `every_test_file_is_a_module`
//! fails while a file is not listed here. Run one file's tests with
//! `cargo test -p proptests --test all FILE::`.

mod robot_file;
mod state;
mod state_reference;
mod updates;
mod walk;
