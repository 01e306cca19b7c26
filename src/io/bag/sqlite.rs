//! rosbag2's SQLite 3 storage (`.db3`): a `topics` table (id, name, type)
//! and a `messages` table (topic id, receive time in ns, CDR bytes), read
//! row by row.

use super::RawMessage;
use super::error::BagError;
use super::storage::Topic;
use rusqlite::{Connection, OpenFlags};
use std::collections::HashMap;
use std::path::Path;

fn open(file: &Path) -> Result<Connection, BagError> {
    Connection::open_with_flags(
        file,
        OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
    .map_err(|e| storage(file, &e))
}

fn storage(file: &Path, e: &rusqlite::Error) -> BagError {
    BagError::Storage {
        bag: file.display().to_string(),
        message: format!("SQLite 3: {e} (a damaged or cut-short .db3?)"),
    }
}

/// The topics of one `.db3` file, with their ids.
fn topics_with_ids(conn: &Connection, file: &Path) -> Result<Vec<(i64, Topic)>, BagError> {
    let mut stmt = conn
        .prepare("SELECT id, name, type FROM topics")
        .map_err(|e| storage(file, &e))?;
    let rows = stmt
        .query_map([], |r| {
            Ok((
                r.get::<_, i64>(0)?,
                Topic {
                    name: r.get(1)?,
                    msg_type: r.get(2)?,
                },
            ))
        })
        .map_err(|e| storage(file, &e))?;
    rows.collect::<Result<_, _>>()
        .map_err(|e| storage(file, &e))
}

/// The topics of one `.db3` file.
pub fn topics(file: &Path) -> Result<Vec<Topic>, BagError> {
    let conn = open(file)?;
    Ok(topics_with_ids(&conn, file)?
        .into_iter()
        .map(|(_, t)| t)
        .collect())
}

/// Calls `f` with each message of the `wanted` topics, in the file's order;
/// `counts` numbers them per topic (across files).
pub fn for_each(
    file: &Path,
    wanted: &[&str],
    counts: &mut HashMap<String, u64>,
    f: &mut dyn FnMut(RawMessage<'_>) -> Result<(), BagError>,
) -> Result<(), BagError> {
    let conn = open(file)?;
    let ids: HashMap<i64, String> = topics_with_ids(&conn, file)?
        .into_iter()
        .filter(|(_, t)| wanted.contains(&t.name.as_str()))
        .map(|(id, t)| (id, t.name))
        .collect();
    if ids.is_empty() {
        return Ok(());
    }
    let list = ids.keys().map(i64::to_string).collect::<Vec<_>>().join(",");
    let sql = format!("SELECT topic_id, timestamp, data FROM messages WHERE topic_id IN ({list})");
    let mut stmt = conn.prepare(&sql).map_err(|e| storage(file, &e))?;
    let mut rows = stmt.query([]).map_err(|e| storage(file, &e))?;
    while let Some(row) = rows.next().map_err(|e| storage(file, &e))? {
        let id: i64 = row.get(0).map_err(|e| storage(file, &e))?;
        let log_time: i64 = row.get(1).map_err(|e| storage(file, &e))?;
        let data = row
            .get_ref(2)
            .and_then(|v| v.as_blob().map_err(Into::into))
            .map_err(|e| storage(file, &e))?;
        let topic = &ids[&id];
        let n = counts.entry(topic.clone()).or_insert(0);
        let index = *n;
        *n += 1;
        f(RawMessage {
            topic,
            index,
            log_time,
            data,
        })?;
    }
    Ok(())
}
