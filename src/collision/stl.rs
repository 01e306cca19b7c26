//! STL triangle meshes (binary and ASCII), as collision geometry reads them.
//!
//! A binary STL is an 80-byte header, a little-endian `u32` triangle count
//! and 50 bytes a triangle (normal, three vertices as `f32`, a `u16`); an
//! ASCII one is `solid … facet normal … outer loop vertex x y z ×3 endloop
//! endfacet … endsolid`. The kind is decided by the size: a file whose
//! length is exactly `84 + 50·count` is binary (some binary files begin
//! with `solid` too). Normals are ignored. Every failure is an error naming
//! the file and what is wrong, never a panic.

/// The triangles of an STL file: three vertices each, in file units.
pub type Triangles = Vec<[[f64; 3]; 3]>;

/// Parses STL bytes; `origin` names the file in errors.
pub fn parse(bytes: &[u8], origin: &str) -> Result<Triangles, String> {
    if bytes.len() >= 84 {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        if 84 + 50 * count == bytes.len() as u64 {
            return binary(bytes, count as usize, origin);
        }
    }
    let head = &bytes[..bytes.len().min(512)];
    let text_start = String::from_utf8_lossy(head);
    if text_start.trim_start().starts_with("solid") {
        return ascii(bytes, origin);
    }
    Err(format!(
        "{origin}: not an STL mesh ({} bytes: neither a binary STL, whose size would be 84 + 50 × its triangle count, nor ASCII starting with 'solid')",
        bytes.len()
    ))
}

fn binary(bytes: &[u8], count: usize, origin: &str) -> Result<Triangles, String> {
    if count == 0 {
        return Err(format!("{origin}: the STL mesh has no triangles"));
    }
    let f = |o: usize| {
        f64::from(f32::from_le_bytes([
            bytes[o],
            bytes[o + 1],
            bytes[o + 2],
            bytes[o + 3],
        ]))
    };
    let mut out = Vec::with_capacity(count);
    for k in 0..count {
        let base = 84 + 50 * k + 12;
        let mut tri = [[0.0; 3]; 3];
        for (v, vert) in tri.iter_mut().enumerate() {
            for (c, x) in vert.iter_mut().enumerate() {
                *x = f(base + 12 * v + 4 * c);
            }
        }
        if tri.iter().flatten().any(|x| !x.is_finite()) {
            return Err(format!(
                "{origin}: triangle {} has a non-finite vertex",
                k + 1
            ));
        }
        out.push(tri);
    }
    Ok(out)
}

fn ascii(bytes: &[u8], origin: &str) -> Result<Triangles, String> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        format!(
            "{origin}: ASCII STL with invalid UTF-8 at byte {}",
            e.valid_up_to()
        )
    })?;
    let mut out = Vec::new();
    let mut cur: Vec<[f64; 3]> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("vertex") => {
                let mut v = [0.0; 3];
                for x in &mut v {
                    *x = it
                        .next()
                        .and_then(|s| s.parse::<f64>().ok())
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| {
                            format!("{origin}:{}: a vertex needs three finite numbers", n + 1)
                        })?;
                }
                cur.push(v);
            }
            Some("endloop") => {
                if cur.len() != 3 {
                    return Err(format!(
                        "{origin}:{}: a facet has {} vertices (STL facets are triangles)",
                        n + 1,
                        cur.len()
                    ));
                }
                out.push([cur[0], cur[1], cur[2]]);
                cur.clear();
            }
            _ => {}
        }
    }
    if out.is_empty() {
        return Err(format!("{origin}: the STL mesh has no triangles"));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binary_of(tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut b = vec![0u8; 80];
        b.extend((tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend([0u8; 12]);
            for v in t {
                for x in v {
                    b.extend(x.to_le_bytes());
                }
            }
            b.extend([0u8; 2]);
        }
        b
    }

    #[test]
    fn binary_and_ascii_give_the_same_triangles() {
        let t = [[[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.5, 0.25]]];
        let b = parse(&binary_of(&t), "b.stl").unwrap();
        let a = parse(
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0.5 0.25\nendloop\nendfacet\nendsolid x\n",
            "a.stl",
        )
        .unwrap();
        assert_eq!(a, b);
        assert_eq!(b[0][2], [0.0, 0.5, 0.25]);
    }

    #[test]
    fn truncated_or_garbage_bytes_are_errors_not_panics() {
        let t = [[[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; 3];
        let full = binary_of(&t);
        for cut in 0..full.len() {
            let r = parse(&full[..cut], "cut.stl");
            assert!(r.is_err(), "{cut} bytes");
            assert!(r.unwrap_err().contains("cut.stl"));
        }
        let mut seed = 1u64;
        for len in [0usize, 10, 84, 134, 500] {
            let junk: Vec<u8> = (0..len)
                .map(|_| {
                    seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
                    (seed >> 56) as u8
                })
                .collect();
            let _ = parse(&junk, "junk.stl");
        }
        assert!(
            parse(b"solid x\nvertex 0 0\nendloop\n", "v.stl")
                .unwrap_err()
                .contains("v.stl:2")
        );
        assert!(parse(b"solid x\nvertex 0 0 nan\n", "n.stl").is_err());
    }
}
