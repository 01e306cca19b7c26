//! A reader of CDR (OMG XCDR1), the encoding rosbag2 stores messages in: a
//! 4-byte encapsulation header (`00 01` little endian, `00 00` big endian,
//! then two option bytes), then the fields, each primitive aligned to its
//! own size relative to the first byte after the header.

/// Why a field could not be read: the caller adds the bag, topic, index
/// and field name.
pub type CdrResult<T> = std::result::Result<T, String>;

/// A cursor over one serialized message.
pub struct Cdr<'a> {
    data: &'a [u8],
    pos: usize,
    little: bool,
}

impl<'a> Cdr<'a> {
    /// Reads the encapsulation header of `data` (plain CDR, either byte
    /// order; XCDR2 and parameter lists are refused).
    pub fn new(data: &'a [u8]) -> CdrResult<Self> {
        if data.len() < 4 {
            return Err(format!(
                "{} byte(s), shorter than the 4-byte CDR header",
                data.len()
            ));
        }
        let little = match (data[0], data[1]) {
            (0, 1) => true,
            (0, 0) => false,
            (a, b) => {
                return Err(format!(
                    "encapsulation {a:02x} {b:02x} is not plain CDR (00 00 or 00 01)"
                ));
            }
        };
        Ok(Self {
            data: &data[4..],
            pos: 0,
            little,
        })
    }

    fn take<const N: usize>(&mut self) -> CdrResult<[u8; N]> {
        // Alignment is to the primitive's size, from the payload's start.
        let pad = (N - self.pos % N) % N;
        let start = self.pos + pad;
        let end = start + N;
        let bytes = self.data.get(start..end).ok_or_else(|| {
            format!(
                "the message ends at byte {} where {N} more byte(s) are needed",
                self.data.len()
            )
        })?;
        self.pos = end;
        let mut out = [0; N];
        out.copy_from_slice(bytes);
        if !self.little {
            out.reverse();
        }
        Ok(out)
    }

    /// An unsigned 32-bit integer.
    pub fn u32(&mut self) -> CdrResult<u32> {
        self.take::<4>().map(u32::from_le_bytes)
    }

    /// A signed 32-bit integer.
    pub fn i32(&mut self) -> CdrResult<i32> {
        self.take::<4>().map(i32::from_le_bytes)
    }

    /// A 64-bit float.
    pub fn f64(&mut self) -> CdrResult<f64> {
        self.take::<8>().map(f64::from_le_bytes)
    }

    /// One byte (a `bool` or `uint8`).
    pub fn u8(&mut self) -> CdrResult<u8> {
        self.take::<1>().map(|b| b[0])
    }

    /// A sequence or string length, checked against the bytes left (each
    /// element at least `min_size` bytes) so a corrupt length cannot ask
    /// for gigabytes.
    fn length(&mut self, min_size: usize) -> CdrResult<usize> {
        let n = self.u32()? as usize;
        let left = self.data.len().saturating_sub(self.pos);
        if n.saturating_mul(min_size) > left {
            return Err(format!(
                "a length of {n} element(s) where only {left} byte(s) are left"
            ));
        }
        Ok(n)
    }

    /// A string: length (with its terminating NUL), bytes, NUL.
    pub fn string(&mut self) -> CdrResult<String> {
        let n = self.length(1)?;
        let bytes = &self.data[self.pos..self.pos + n];
        self.pos += n;
        let text = bytes.strip_suffix(&[0]).unwrap_or(bytes);
        String::from_utf8(text.to_vec()).map_err(|_| "a string that is not UTF-8".to_string())
    }

    /// A sequence of strings.
    pub fn strings(&mut self) -> CdrResult<Vec<String>> {
        let n = self.length(4)?;
        (0..n).map(|_| self.string()).collect()
    }

    /// A sequence of 64-bit floats.
    pub fn f64s(&mut self) -> CdrResult<Vec<f64>> {
        let n = self.length(8)?;
        (0..n).map(|_| self.f64()).collect()
    }

    /// `N` 64-bit floats (a fixed-size array: no length).
    pub fn f64_array<const N: usize>(&mut self) -> CdrResult<[f64; N]> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = self.f64()?;
        }
        Ok(out)
    }

    /// A sequence of bytes (an image's pixels), borrowed from the message.
    pub fn bytes(&mut self) -> CdrResult<&'a [u8]> {
        let n = self.length(1)?;
        let b = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(b)
    }

    /// The number of elements of a sequence (its length field only).
    pub fn sequence_len(&mut self, min_size: usize) -> CdrResult<usize> {
        self.length(min_size)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A string then a float, by hand: the float is aligned to 8 from the
    /// payload's start (not the buffer's), in both byte orders.
    #[test]
    fn alignment_is_relative_to_the_payload() {
        let mut le = vec![0, 1, 0, 0];
        le.extend(2u32.to_le_bytes());
        le.extend(b"a\0");
        le.extend([0; 2]); // to offset 8 of the payload
        le.extend(1.5f64.to_le_bytes());
        let mut c = Cdr::new(&le).unwrap();
        assert_eq!(c.string().unwrap(), "a");
        assert_eq!(c.f64().unwrap(), 1.5);
        let mut be = vec![0, 0, 0, 0];
        be.extend(2u32.to_be_bytes());
        be.extend(b"a\0");
        be.extend([0; 2]);
        be.extend((-2.25f64).to_be_bytes());
        let mut c = Cdr::new(&be).unwrap();
        assert_eq!(c.string().unwrap(), "a");
        assert_eq!(c.f64().unwrap(), -2.25);
    }

    #[test]
    fn a_short_or_corrupt_message_is_an_error() {
        assert!(Cdr::new(&[0, 1]).is_err());
        let mut c = Cdr::new(&[0, 1, 0, 0, 0xff, 0xff, 0xff, 0x7f]).unwrap();
        assert!(c.string().unwrap_err().contains("only 0 byte(s)"));
        let mut c = Cdr::new(&[0, 1, 0, 0, 1, 2]).unwrap();
        assert!(c.f64().unwrap_err().contains("ends at byte 2"));
        assert!(Cdr::new(&[0, 7, 0, 0]).is_err());
    }
}
