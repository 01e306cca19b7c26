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

/// Calls `f` with every record of the file, in order; returns the largest
/// read the reader asked for at once (bytes): a chunk's, never the file's.
fn stream(
    file: &Path,
    f: &mut dyn FnMut(Record<'_>) -> Result<(), BagError>,
) -> Result<usize, BagError> {
    let mut input = std::fs::File::open(file).map_err(io(file))?;
    let mut reader = LinearReader::new();
    let mut largest = 0;
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| storage(file, format!("MCAP: {e}")))? {
            LinearReadEvent::ReadRequest(need) => {
                largest = largest.max(need);
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
    Ok(largest)
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
    .map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bag of 24 MB, 1 MB chunks of a camera's 100 kB messages beside
    /// 1 kHz joint states, is read as a stream: every joint message
    /// reaches the caller, and the reader never asks for more than a
    /// chunk and a message at once (2 MB), an eighth of the file; the
    /// 2 GB figure (peak memory) is benches/bag_memory.sh's.
    #[test]
    fn a_bag_is_read_a_chunk_at_a_time() {
        let path =
            std::env::temp_dir().join(format!("activecal-stream-{}.mcap", std::process::id()));
        let out = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
        let mut w = mcap::WriteOptions::new()
            .compression(None)
            .chunk_size(Some(1 << 20))
            .create(out)
            .unwrap();
        let schema = w
            .add_schema("sensor_msgs/msg/JointState", "ros2msg", b"")
            .unwrap();
        let joints = w
            .add_channel(schema, "/joint_states", "cdr", &Default::default())
            .unwrap();
        let image = w
            .add_schema("sensor_msgs/msg/Image", "ros2msg", b"")
            .unwrap();
        let camera = w
            .add_channel(image, "/camera", "cdr", &Default::default())
            .unwrap();
        let frame = vec![7u8; 100_000];
        let (mut sent, mut k) = (0u64, 0u32);
        for i in 0..240u64 {
            for j in 0..33u64 {
                let t = i * 33_000_000 + j * 1_000_000;
                let header = mcap::records::MessageHeader {
                    channel_id: joints,
                    sequence: k,
                    log_time: t,
                    publish_time: t,
                };
                w.write_to_known_channel(&header, &t.to_le_bytes()).unwrap();
                sent += 1;
                k += 1;
            }
            let t = i * 33_000_000;
            let header = mcap::records::MessageHeader {
                channel_id: camera,
                sequence: k,
                log_time: t,
                publish_time: t,
            };
            w.write_to_known_channel(&header, &frame).unwrap();
            k += 1;
        }
        w.finish().unwrap();
        drop(w);
        let size = std::fs::metadata(&path).unwrap().len() as usize;
        let mut seen = 0u64;
        let largest = stream(&path, &mut |r| {
            if matches!(r, Record::Message { ref header, .. } if header.channel_id == joints) {
                seen += 1;
            }
            Ok(())
        })
        .unwrap();
        let mut counts = HashMap::new();
        let mut got = 0u64;
        for_each(&path, &["/joint_states"], &mut counts, &mut |m| {
            assert_eq!(m.data.len(), 8, "a joint message's bytes");
            got += 1;
            Ok(())
        })
        .unwrap();
        std::fs::remove_file(&path).unwrap();
        assert!(size > 24_000_000, "{size} bytes");
        assert_eq!((seen, got, counts["/joint_states"]), (sent, sent, sent));
        assert!(
            largest <= 2 << 20,
            "the reader asked for {largest} bytes at once of {size}"
        );
    }
}
