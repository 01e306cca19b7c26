//! ROS 2 bags (rosbag2): MCAP and SQLite 3 storage, read as streams, their
//! messages decoded from CDR by a reader of our own ([`cdr`],
//! [`messages`]); no ROS installation is needed. [`series`] gathers the
//! joint and measurement streams a calibration run records, [`rest`] finds
//! the poses (the periods the arm stands still) and averages each
//! measurement over its rest, [`clock`] estimates the offset between the
//! two streams' clocks from the moves, and [`extract`] turns a bag into
//! [`crate::data::Measurements`] with a report of what was kept and why.

pub mod camera;
pub mod cdr;
pub mod clock;
pub mod design;
pub mod error;
pub mod extract;
pub mod image;
mod mcap_file;
pub mod messages;
pub mod rest;
pub mod series;
mod sqlite;
pub mod storage;
pub mod tf;
pub mod timeseries;

pub use error::BagError;
pub use storage::{Format, Topic};

use std::collections::HashMap;
use std::path::Path;
use storage::Storage;

/// One stored message: its topic, its 0-based index on the topic, the time
/// the recorder received it (ns) and its CDR bytes.
#[derive(Clone, Copy, Debug)]
pub struct RawMessage<'a> {
    /// The topic.
    pub topic: &'a str,
    /// 0-based index of the message on its topic.
    pub index: u64,
    /// The recorder's receive time (ns since the epoch).
    pub log_time: i64,
    /// The serialized message (CDR).
    pub data: &'a [u8],
}

/// An opened bag: where its messages are and which topics it holds.
#[derive(Clone, Debug)]
pub struct Bag {
    storage: Storage,
    topics: Vec<Topic>,
}

impl Bag {
    /// Opens the bag at `path` (a rosbag2 folder, or one `.mcap` or `.db3`
    /// file) and reads its topics; a damaged or cut-short file is refused
    /// here, before any message is read.
    pub fn open(path: &Path) -> Result<Self, BagError> {
        let storage = Storage::locate(path)?;
        let mut topics: Vec<Topic> = Vec::new();
        for file in &storage.files {
            let found = match storage.format {
                Format::Mcap => mcap_file::topics(file)?,
                Format::Sqlite => sqlite::topics(file)?,
            };
            for t in found {
                if !topics.iter().any(|k| k.name == t.name) {
                    topics.push(t);
                }
            }
        }
        Ok(Self { storage, topics })
    }

    /// The bag as given (for messages).
    #[must_use]
    pub fn name(&self) -> &str {
        &self.storage.name
    }

    /// The storage format.
    #[must_use]
    pub fn format(&self) -> Format {
        self.storage.format
    }

    /// The bag's topics with their types.
    #[must_use]
    pub fn topics(&self) -> &[Topic] {
        &self.topics
    }

    /// The topic named `name`, checked to be of one of the `types`; a
    /// missing topic is an error listing the bag's topics, one of another
    /// type an error naming its type.
    pub fn topic(&self, name: &str, types: &[&str]) -> Result<&Topic, BagError> {
        let Some(t) = self.topics.iter().find(|t| t.name == name) else {
            let known = self
                .topics
                .iter()
                .map(|t| format!("{} ({})", t.name, t.msg_type))
                .collect::<Vec<_>>()
                .join(", ");
            return Err(BagError::MissingTopic {
                bag: self.name().to_string(),
                topic: name.to_string(),
                known: if known.is_empty() {
                    "none".into()
                } else {
                    known
                },
            });
        };
        if !types.contains(&t.msg_type.as_str()) {
            return Err(BagError::WrongType {
                bag: self.name().to_string(),
                topic: name.to_string(),
                found: t.msg_type.clone(),
                expected: types.join(" or "),
            });
        }
        Ok(t)
    }

    /// Calls `f` with every message of the `wanted` topics, file by file in
    /// storage order, streaming (one message, or one MCAP chunk, in memory
    /// at a time).
    pub fn for_each(
        &self,
        wanted: &[&str],
        mut f: impl FnMut(RawMessage<'_>) -> Result<(), BagError>,
    ) -> Result<(), BagError> {
        let mut counts = HashMap::new();
        for file in &self.storage.files {
            match self.storage.format {
                Format::Mcap => mcap_file::for_each(file, wanted, &mut counts, &mut f)?,
                Format::Sqlite => sqlite::for_each(file, wanted, &mut counts, &mut f)?,
            }
        }
        Ok(())
    }

    /// A decoding error of message `m` at `field` (see [`messages`]).
    #[must_use]
    pub fn decode_error(
        &self,
        m: &RawMessage<'_>,
        (field, message): messages::FieldError,
    ) -> BagError {
        BagError::Decode {
            bag: self.name().to_string(),
            topic: m.topic.to_string(),
            index: m.index,
            field: field.to_string(),
            message,
        }
    }

    /// An error about the bag's content.
    #[must_use]
    pub fn content_error(&self, message: String) -> BagError {
        BagError::Content {
            bag: self.name().to_string(),
            message,
        }
    }
}
