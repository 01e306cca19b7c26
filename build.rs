//! Embeds three.js into the binary for the 3D page of report folders
//! (`src/render/page/`): the files of `web/node_modules/three` (installed by
//! `scripts/setup`, `npm ci` in `web/`, pinned by `web/package-lock.json`)
//! are copied into `OUT_DIR` and `include_str!`-ed. Without them the build
//! still succeeds: the page then shows its tables and figures and says that
//! the 3D view needs `scripts/setup` and a rebuild (cfg `activecal_three`
//! unset, and a cargo warning here says so).

use std::path::{Path, PathBuf};
use std::{env, fs};

/// three.js files the page uses: path in the package, name in `OUT_DIR`.
const FILES: [(&str, &str); 4] = [
    ("build/three.core.js", "three.core.js"),
    ("build/three.module.js", "three.module.js"),
    ("examples/jsm/controls/OrbitControls.js", "OrbitControls.js"),
    ("LICENSE", "three.LICENSE"),
];

fn main() {
    let root =
        PathBuf::from(env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let out = PathBuf::from(env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let three = root.join("web/node_modules/three");
    println!("cargo::rustc-check-cfg=cfg(activecal_three)");
    println!("cargo::rerun-if-changed=web/package-lock.json");
    println!("cargo::rerun-if-changed=web/node_modules/three/package.json");
    // Written afresh by every `npm ci` (scripts/setup): a reinstall is seen
    // even when three's own files keep their times.
    println!("cargo::rerun-if-changed=web/node_modules/.package-lock.json");
    let have = FILES.iter().all(|(f, _)| three.join(f).is_file());
    for (from, to) in FILES {
        let text = if have {
            read(&three.join(from))
        } else {
            String::new()
        };
        fs::write(out.join(to), text).expect("OUT_DIR is writable");
    }
    let version = if have {
        let pkg = read(&three.join("package.json"));
        pkg.split("\"version\"")
            .nth(1)
            .and_then(|s| s.split('"').nth(1))
            .unwrap_or("")
            .to_string()
    } else {
        String::new()
    };
    fs::write(out.join("three.version"), version).expect("OUT_DIR is writable");
    if have {
        println!("cargo::rustc-cfg=activecal_three");
    } else {
        println!(
            "cargo::warning=web/node_modules/three is missing: report pages will have no 3D view. Run scripts/setup (it runs `npm ci` in web/) and build again."
        );
    }
}

fn read(p: &Path) -> String {
    fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}
