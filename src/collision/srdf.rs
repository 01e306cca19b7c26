//! The `disable_collisions` pairs of an SRDF file (MoveIt's semantic robot
//! description): `<disable_collisions link1="A" link2="B" reason="…"/>`.
//! Only those elements are read; each pair keeps its line for errors (an
//! SRDF naming a link the URDF does not have).

/// One disabled pair with the 1-based line it is on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DisabledPair {
    /// First link.
    pub link1: String,
    /// Second link.
    pub link2: String,
    /// Line of the element in the file.
    pub line: usize,
}

/// Reads the disabled pairs of SRDF text; `origin` names the file in errors.
pub fn disabled_pairs(text: &str, origin: &str) -> Result<Vec<DisabledPair>, String> {
    let mut out = Vec::new();
    let mut rest = text;
    let mut consumed = 0usize;
    while let Some(k) = rest.find("<disable_collisions") {
        let start = consumed + k;
        let line = text[..start].matches('\n').count() + 1;
        let after = &text[start..];
        let end = after
            .find('>')
            .ok_or_else(|| format!("{origin}:{line}: unterminated <disable_collisions> element"))?;
        let tag = &after[..end];
        let attr = |name: &str| -> Result<String, String> {
            let key = format!("{name}=");
            let i = tag
                .find(&key)
                .ok_or_else(|| format!("{origin}:{line}: <disable_collisions> without {name}"))?;
            let v = &tag[i + key.len()..];
            let q = v
                .chars()
                .next()
                .filter(|c| *c == '"' || *c == '\'')
                .ok_or_else(|| {
                    format!("{origin}:{line}: the {name} of <disable_collisions> is not quoted")
                })?;
            let close = v[1..]
                .find(q)
                .ok_or_else(|| format!("{origin}:{line}: unterminated {name} value"))?;
            Ok(v[1..1 + close].to_string())
        };
        out.push(DisabledPair {
            link1: attr("link1")?,
            link2: attr("link2")?,
            line,
        });
        consumed = start + end;
        rest = &text[consumed..];
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_pairs_with_their_lines_and_refuses_broken_elements() {
        let t = "<robot>\n  <disable_collisions link1=\"a\" link2='b' reason=\"Adjacent\"/>\n\n<disable_collisions link2=\"d\" link1=\"c\"/>\n</robot>";
        let p = disabled_pairs(t, "r.srdf").unwrap();
        assert_eq!(p.len(), 2);
        assert_eq!(
            (p[0].link1.as_str(), p[0].link2.as_str(), p[0].line),
            ("a", "b", 2)
        );
        assert_eq!(
            (p[1].link1.as_str(), p[1].link2.as_str(), p[1].line),
            ("c", "d", 4)
        );
        assert!(
            disabled_pairs("<disable_collisions link1=\"a\"/>", "x")
                .unwrap_err()
                .contains("link2")
        );
        assert!(
            disabled_pairs("\n<disable_collisions link1=a link2=\"b\"/>", "x")
                .unwrap_err()
                .contains("x:2")
        );
        assert!(disabled_pairs("<disable_collisions link1=\"a", "x").is_err());
    }
}
