//! Text encodings the page needs: base64 (meshes, PNG figures), HTML
//! escaping, and text safe inside a `<script>` element.

/// Standard base64 (RFC 4648, padded) of `bytes`.
#[must_use]
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// `text` with `&`, `<`, `>` and `"` escaped for HTML text and attributes.
#[must_use]
pub fn html(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// JavaScript text that cannot end the `<script>` element holding it:
/// `</` becomes `<\/` and `<!--` becomes `<\!--` (the same characters in
/// JS string literals, regular expressions and comments, where they occur).
#[must_use]
pub fn script(text: &str) -> String {
    text.replace("</", "<\\/").replace("<!--", "<\\!--")
}

/// JSON text that cannot end the `<script>` element holding it: `</`
/// becomes `<\/` and `<!--` becomes `<\u0021--`, both JSON escapes of
/// the same characters.
#[must_use]
pub fn json_script(text: &str) -> String {
    text.replace("</", "<\\/").replace("<!--", "<\\u0021--")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648_vectors() {
        // RFC 4648 §10.
        for (i, o) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(i.as_bytes()), o);
        }
    }

    #[test]
    fn script_text_cannot_close_its_element() {
        let raw = r#"{"a":"</script><!--"}"#;
        for s in [script(raw), json_script(raw)] {
            assert!(!s.to_ascii_lowercase().contains("</script"), "{s}");
            assert!(!s.contains("<!--"), "{s}");
        }
        let v: serde_json::Value = serde_json::from_str(&json_script(raw)).unwrap();
        assert_eq!(v["a"], "</script><!--");
    }
}
