//! rosbag2's MCAP storage, read as a stream (the `mcap` crate's sans-io
//! reader fed from the file a buffer at a time, chunks decompressed one at
//! a time), so a bag of any size is read in bounded memory.

use super::RawMessage;
use super::error::BagError;
use super::storage::Topic;
use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader};
use std::collections::HashMap;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

const MAGIC: &[u8] = b"\x89MCAP0\r\n";
/// The footer record: opcode, length, summary start, summary offset start,
/// summary CRC.
const FOOTER_LEN: u64 = 1 + 8 + 8 + 8 + 4;

fn storage(file: &Path, message: String) -> BagError {
    BagError::Storage {
        bag: file.display().to_string(),
        message,
    }
}

fn io(file: &Path) -> impl Fn(std::io::Error) -> BagError + '_ {
    move |cause| BagError::Io {
        bag: file.display().to_string(),
        cause,
    }
}

/// Where the summary section starts, read from the footer; a file that does
/// not end in MCAP's magic is refused as cut short.
fn summary_start(f: &mut std::fs::File, file: &Path) -> Result<(u64, u64), BagError> {
    let len = f.metadata().map_err(io(file))?.len();
    let tail = FOOTER_LEN + MAGIC.len() as u64;
    let truncated = || {
        storage(
            file,
            format!(
                "MCAP: the file ({len} bytes) does not end with MCAP's footer and closing magic: cut short (a recording that did not finish, or a partial copy?)"
            ),
        )
    };
    if len < tail + MAGIC.len() as u64 {
        return Err(truncated());
    }
    f.seek(SeekFrom::Start(len - tail)).map_err(io(file))?;
    let mut buf = vec![0u8; tail as usize];
    f.read_exact(&mut buf).map_err(io(file))?;
    if &buf[FOOTER_LEN as usize..] != MAGIC || buf[0] != 0x02 {
        return Err(truncated());
    }
    let start = u64::from_le_bytes(buf[9..17].try_into().expect("8 bytes"));
    Ok((start, len - tail))
}

/// The topics of one MCAP file, from its summary section's channels and
/// schemas (a file without a summary is scanned).
pub fn topics(file: &Path) -> Result<Vec<Topic>, BagError> {
    let mut f = std::fs::File::open(file).map_err(io(file))?;
    let (start, end) = summary_start(&mut f, file)?;
    let mut schemas = HashMap::new();
    let mut channels = Vec::new();
    if start == 0 {
        // No summary: every record is visited once.
        let mut note = |r: &Record<'_>| note_topic(r, &mut schemas, &mut channels);
        stream(file, &mut |r| {
            note(&r);
            Ok(())
        })?;
    } else {
        f.seek(SeekFrom::Start(start)).map_err(io(file))?;
        let mut buf = vec![0u8; (end - start) as usize];
        f.read_exact(&mut buf).map_err(io(file))?;
        let mut at = 0usize;
        while at + 9 <= buf.len() {
            let op = buf[at];
            let n = u64::from_le_bytes(buf[at + 1..at + 9].try_into().expect("8 bytes")) as usize;
            let body = buf.get(at + 9..at + 9 + n).ok_or_else(|| {
                storage(file, "MCAP: a summary record runs past its section".into())
            })?;
            let r = mcap::parse_record(op, body)
                .map_err(|e| storage(file, format!("MCAP summary: {e}")))?;
            note_topic(&r, &mut schemas, &mut channels);
            at += 9 + n;
        }
    }
    Ok(channels
        .into_iter()
        .map(|(name, schema)| Topic {
            name,
            msg_type: schemas.get(&schema).cloned().unwrap_or_default(),
        })
        .collect())
}

fn note_topic(
    r: &Record<'_>,
    schemas: &mut HashMap<u16, String>,
    channels: &mut Vec<(String, u16)>,
) {
    match r {
        Record::Schema { header, .. } => {
            schemas.insert(header.id, header.name.clone());
        }
        Record::Channel(c) if !channels.iter().any(|(t, _)| *t == c.topic) => {
            channels.push((c.topic.clone(), c.schema_id));
        }
        _ => {}
    }
}

/// Calls `f` with every record of the file, in order.
fn stream(
    file: &Path,
    f: &mut dyn FnMut(Record<'_>) -> Result<(), BagError>,
) -> Result<(), BagError> {
    let mut input = std::fs::File::open(file).map_err(io(file))?;
    let mut reader = LinearReader::new();
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| storage(file, format!("MCAP: {e}")))? {
            LinearReadEvent::ReadRequest(need) => {
                let n = input.read(reader.insert(need)).map_err(io(file))?;
                reader.notify_read(n);
            }
            LinearReadEvent::Record { opcode, data } => {
                let r = mcap::parse_record(opcode, data)
                    .map_err(|e| storage(file, format!("MCAP: {e}")))?;
                f(r)?;
            }
        }
    }
    Ok(())
}

/// Calls `f` with each message of the `wanted` topics, in the file's order;
/// `counts` numbers them per topic (across files).
pub fn for_each(
    file: &Path,
    wanted: &[&str],
    counts: &mut HashMap<String, u64>,
    f: &mut dyn FnMut(RawMessage<'_>) -> Result<(), BagError>,
) -> Result<(), BagError> {
    // The footer first: a cut-short file is refused before any work.
    summary_start(&mut std::fs::File::open(file).map_err(io(file))?, file)?;
    let mut channels: HashMap<u16, String> = HashMap::new();
    stream(file, &mut |r| match r {
        Record::Channel(c) => {
            if wanted.contains(&c.topic.as_str()) {
                channels.insert(c.id, c.topic);
            }
            Ok(())
        }
        Record::Message { header, data } => {
            let Some(topic) = channels.get(&header.channel_id) else {
                return Ok(());
            };
            let n = counts.entry(topic.clone()).or_insert(0);
            let index = *n;
            *n += 1;
            f(RawMessage {
                topic,
                index,
                log_time: i64::try_from(header.log_time).unwrap_or(i64::MAX),
                data: &data,
            })
        }
        _ => Ok(()),
    })
}
