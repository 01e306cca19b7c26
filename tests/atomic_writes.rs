//! A kill (SIGKILL) at a random moment of a write never leaves a partial
//! output file and never loses the old one: this test re-runs its own binary
//! as a writer that replaces a 4 MB file in a loop with
//! `activecal::io::atomic::write_atomic`, kills it after a random delay, and
//! checks that the file is one whole generation, old or new.

use rand::{RngExt, SeedableRng};
use std::path::Path;
use std::process::Command;
use std::time::Duration;

const SIZE: usize = 4 << 20;
const WRITER: &str = "ACTIVECAL_TEST_ATOMIC_WRITER";

/// A file of generation `g`: `SIZE` bytes, every one equal to `g % 251`.
fn generation(g: u64) -> Vec<u8> {
    vec![(g % 251) as u8; SIZE]
}

/// The generation of a whole file, or a description of what is wrong.
fn whole(path: &Path) -> Result<u8, String> {
    let b = std::fs::read(path).map_err(|e| format!("unreadable: {e}"))?;
    if b.len() != SIZE {
        return Err(format!("{} bytes, not {SIZE}", b.len()));
    }
    let g = b[0];
    if b.iter().any(|&x| x != g) {
        return Err("bytes of two generations".into());
    }
    Ok(g)
}

#[test]
fn writer_process() {
    // Runs only as the child of `kill_during_writes_never_leaves_a_partial_file`.
    let Some(path) = std::env::var_os(WRITER) else {
        return;
    };
    let path = Path::new(&path);
    for g in 1.. {
        activecal::io::atomic::write_atomic(path, &generation(g)).unwrap();
    }
}

#[test]
fn kill_during_writes_never_leaves_a_partial_file() {
    let dir = std::env::temp_dir().join(format!("activecal-kill-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let target = dir.join("design.json");
    std::fs::write(&target, generation(0)).unwrap();
    let exe = std::env::current_exe().unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    // The writer test's name in this binary: its module path without the
    // crate's name.
    let writer = module_path!()
        .split_once("::")
        .map_or("writer_process".to_string(), |(_, m)| {
            format!("{m}::writer_process")
        });
    let mut advanced = 0;
    for round in 0..12 {
        let mut child = Command::new(&exe)
            .args([
                "--exact",
                writer.as_str(),
                "--nocapture",
                "--test-threads=1",
            ])
            .env(WRITER, &target)
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(rng.random_range(20..200)));
        child.kill().unwrap(); // SIGKILL on Unix
        child.wait().unwrap();
        let g = whole(&target).unwrap_or_else(|e| panic!("round {round}: {e}"));
        advanced += usize::from(g != 0);
        // No temporary file is taken for the output; leftovers of killed
        // writers are hidden dot-files beside it, never the output itself.
        assert!(target.exists());
    }
    // The writer did replace the file (the test exercised real writes).
    assert!(advanced > 0, "the writer never completed a write");
    std::fs::remove_dir_all(&dir).unwrap();
}
