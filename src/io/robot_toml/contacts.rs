//! The `[[distance]]` and `[[plane]]` tables of a description: what a
//! calibration from contacts knows of its setup.

use super::spec::{Ctx, FileSpec};
use crate::error::Result;

/// The `[[distance]]` and `[[plane]]` tables, checked: a distance between
/// two different points, finite and > 0; a plane with a finite, non-zero
/// normal and a finite offset (each error at its table's line).
pub(super) fn contact_setup(cx: &Ctx<'_>, spec: &FileSpec) -> Result<crate::io::ContactSetup> {
    let mut setup = crate::io::ContactSetup::default();
    for d in &spec.distance {
        let v = d.get_ref();
        if v.a == v.b || !(v.metres.is_finite() && v.metres > 0.0) {
            return Err(cx.at(
                d.span(),
                format!(
                    "[[distance]] {},{}={}: a distance needs two different points and a finite length > 0 (metres)",
                    v.a, v.b, v.metres
                ),
            ));
        }
        setup.distances.push(crate::data::NamedDistance {
            a: v.a.clone(),
            b: v.b.clone(),
            metres: v.metres,
        });
    }
    for p in &spec.plane {
        let v = p.get_ref();
        let n2: f64 = v.normal.iter().map(|c| c * c).sum();
        if !(n2.is_finite() && n2 > 0.0 && v.offset.is_finite()) {
            return Err(cx.at(
                p.span(),
                format!(
                    "[[plane]] '{}': a plane needs a finite, non-zero normal and a finite offset (metres)",
                    v.name
                ),
            ));
        }
        setup.planes.push(crate::data::NamedPlane {
            name: v.name.clone(),
            normal: v.normal,
            offset: v.offset,
        });
    }
    Ok(setup)
}
