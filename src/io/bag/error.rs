//! What can be wrong with a bag: every message names the bag, and where it
//! can the topic, the message's index on its topic and the field.

use thiserror::Error;

/// A bag that cannot be read or does not hold what was asked of it.
#[derive(Debug, Error)]
pub enum BagError {
    /// The bag's file (or folder) cannot be read.
    #[error("{bag}: {cause}")]
    Io {
        /// The bag.
        bag: String,
        /// The underlying error.
        cause: std::io::Error,
    },
    /// A storage format other than MCAP and SQLite 3.
    #[error("{bag}: storage plugin '{plugin}' is not read (rosbag2's 'mcap' and 'sqlite3' are)")]
    UnknownStorage {
        /// The bag.
        bag: String,
        /// The storage identifier found (or the file's extension).
        plugin: String,
    },
    /// The storage file is damaged or cut short.
    #[error("{bag}: {message}")]
    Storage {
        /// The bag (or its storage file).
        bag: String,
        /// What is wrong.
        message: String,
    },
    /// A topic the bag does not have.
    #[error("{bag}: no topic '{topic}' (the bag's topics: {known})")]
    MissingTopic {
        /// The bag.
        bag: String,
        /// The topic asked for.
        topic: String,
        /// The bag's topics with their types.
        known: String,
    },
    /// A topic of another message type than the one asked for.
    #[error("{bag}: topic '{topic}' is of type {found}, not {expected}")]
    WrongType {
        /// The bag.
        bag: String,
        /// The topic.
        topic: String,
        /// Its type in the bag.
        found: String,
        /// The type(s) that would be read.
        expected: String,
    },
    /// A message whose bytes do not decode as its type.
    #[error("{bag}: topic '{topic}', message {index}: field '{field}': {message}")]
    Decode {
        /// The bag.
        bag: String,
        /// The topic.
        topic: String,
        /// 0-based index of the message on its topic.
        index: u64,
        /// The field being read.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The bag's data cannot give what was asked (a joint never published,
    /// no rest period, a transform that is never given).
    #[error("{bag}: {message}")]
    Content {
        /// The bag.
        bag: String,
        /// What is missing, and where.
        message: String,
    },
}

impl From<BagError> for crate::error::Error {
    fn from(e: BagError) -> Self {
        let (path, message) = match &e {
            BagError::Io { bag, cause } => {
                return crate::error::Error::Io {
                    path: bag.clone(),
                    cause: std::io::Error::new(cause.kind(), cause.to_string()),
                };
            }
            BagError::UnknownStorage { bag, .. }
            | BagError::Storage { bag, .. }
            | BagError::MissingTopic { bag, .. }
            | BagError::WrongType { bag, .. }
            | BagError::Decode { bag, .. }
            | BagError::Content { bag, .. } => (bag.clone(), e.to_string()),
        };
        // The message already begins with the bag's name.
        let message = message
            .strip_prefix(&format!("{path}: "))
            .unwrap_or(&message)
            .to_string();
        crate::error::Error::Parse { path, message }
    }
}
