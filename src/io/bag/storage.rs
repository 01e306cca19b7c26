//! Where a bag's messages are: a rosbag2 folder (its `metadata.yaml` names
//! the storage plugin and files) or one `.mcap` / `.db3` file, and the
//! topics it holds.

use super::error::BagError;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The storage formats read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// MCAP (rosbag2's default since Iron).
    Mcap,
    /// SQLite 3 (`.db3`, the default before Iron).
    Sqlite,
}

/// A topic of a bag.
#[derive(Clone, Debug, PartialEq)]
pub struct Topic {
    /// Its name (`/joint_states`).
    pub name: String,
    /// Its message type (`sensor_msgs/msg/JointState`).
    pub msg_type: String,
}

/// The storage files of a bag, in order, and their format.
#[derive(Clone, Debug)]
pub struct Storage {
    /// The bag as given (a folder or a file), for messages.
    pub name: String,
    /// The format of every file.
    pub format: Format,
    /// The files, in recording order.
    pub files: Vec<PathBuf>,
}

#[derive(Deserialize)]
struct MetadataFile {
    rosbag2_bagfile_information: Metadata,
}

#[derive(Deserialize)]
struct Metadata {
    storage_identifier: String,
    #[serde(default)]
    relative_file_paths: Vec<String>,
}

const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";
const SQLITE_MAGIC: &[u8] = b"SQLite format 3\0";

impl Storage {
    /// Finds the storage of the bag at `path`: a folder with a
    /// `metadata.yaml` (or, without one, its `.mcap` or `.db3` files), or
    /// one storage file, told by its first bytes.
    pub fn locate(path: &Path) -> Result<Self, BagError> {
        let name = path.display().to_string();
        let io = |cause| BagError::Io {
            bag: name.clone(),
            cause,
        };
        let meta = std::fs::metadata(path).map_err(io)?;
        if !meta.is_dir() {
            let format = sniff(path, &name)?;
            return Ok(Self {
                name,
                format,
                files: vec![path.to_path_buf()],
            });
        }
        let yaml = path.join("metadata.yaml");
        if yaml.exists() {
            let text = crate::io::read::read_text(&yaml).map_err(|e| BagError::Storage {
                bag: name.clone(),
                message: e.to_string(),
            })?;
            let m: MetadataFile = serde_saphyr::from_str(&text).map_err(|e| BagError::Storage {
                bag: name.clone(),
                message: format!("metadata.yaml: {e}"),
            })?;
            let m = m.rosbag2_bagfile_information;
            let format = match m.storage_identifier.as_str() {
                "mcap" => Format::Mcap,
                "sqlite3" => Format::Sqlite,
                other => {
                    return Err(BagError::UnknownStorage {
                        bag: name,
                        plugin: other.to_string(),
                    });
                }
            };
            let files = m.relative_file_paths.iter().map(|f| path.join(f)).collect();
            return Ok(Self {
                name,
                format,
                files,
            });
        }
        let mut files: Vec<PathBuf> = std::fs::read_dir(path)
            .map_err(io)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "mcap" || e == "db3"))
            .collect();
        files.sort();
        let Some(first) = files.first() else {
            return Err(BagError::Storage {
                bag: name,
                message: "a folder with neither metadata.yaml nor .mcap or .db3 files".into(),
            });
        };
        let format = sniff(first, &name)?;
        Ok(Self {
            name,
            format,
            files,
        })
    }
}

/// The format of one storage file, by its first bytes.
fn sniff(file: &Path, bag: &str) -> Result<Format, BagError> {
    use std::io::Read;
    let mut head = [0u8; 16];
    let mut f = std::fs::File::open(file).map_err(|cause| BagError::Io {
        bag: file.display().to_string(),
        cause,
    })?;
    let n = f.read(&mut head).map_err(|cause| BagError::Io {
        bag: bag.to_string(),
        cause,
    })?;
    if head[..n].starts_with(MCAP_MAGIC) {
        Ok(Format::Mcap)
    } else if head[..n].starts_with(SQLITE_MAGIC) {
        Ok(Format::Sqlite)
    } else {
        let ext = file.extension().map_or_else(
            || "(none)".to_string(),
            |e| e.to_string_lossy().into_owned(),
        );
        Err(BagError::UnknownStorage {
            bag: bag.to_string(),
            plugin: format!("file extension .{ext}, neither MCAP nor SQLite 3 bytes"),
        })
    }
}
