//! The one way every algorithm's settings are built: `X::builder()`, one
//! setter per field, then `build()`, which runs `X::validate` (as Clarabel's
//! settings builder does). `settings_builder!` writes the builder for a
//! settings type that has a `Default` and a `validate(&self) -> Result<(), E>`.

/// Writes `$builder` for `$settings`: `$settings::builder()` starting from
/// `Default`, a setter per listed field (with the doc given) and `build()`
/// returning the settings checked by `$settings::validate`.
macro_rules! settings_builder {
    (
        $(#[$bm:meta])*
        $builder:ident for $settings:ident, error $err:ty {
            $( $(#[$fm:meta])* $field:ident : $ty:ty ),* $(,)?
        }
    ) => {
        $(#[$bm])*
        #[derive(Clone, Debug)]
        #[must_use]
        pub struct $builder($settings);

        impl $settings {
            /// A builder starting from the documented defaults
            /// ([`Default`]); its `build` validates.
            pub fn builder() -> $builder {
                $builder(<$settings as ::core::default::Default>::default())
            }

            /// A builder starting from these settings.
            pub fn into_builder(self) -> $builder {
                $builder(self)
            }
        }

        impl $builder {
            $(
                $(#[$fm])*
                pub fn $field(mut self, v: $ty) -> Self {
                    self.0.$field = v;
                    self
                }
            )*

            /// The settings, checked by `validate`.
            pub fn build(self) -> ::core::result::Result<$settings, $err> {
                self.0.validate()?;
                Ok(self.0)
            }
        }
    };
}

pub(crate) use settings_builder;

/// A setting given a value it cannot take, or with another setting that
/// rules it out: named by its key (the settings field's name, which is
/// also the Python keyword: `loss_scale`), with the value given and why.
/// Other settings `why` mentions are written as their keys in backticks
/// (`` `loss` ``), so that each front end spells them its own way (the
/// command line `--loss`, Python `loss`): the library names no flag.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("`{key}`{}: {why}", value.as_ref().map_or(String::new(), |v| format!(" {v}")))]
pub struct SettingError {
    /// The setting's key.
    pub key: &'static str,
    /// The value given, as given (none: the setting was missing).
    pub value: Option<String>,
    /// Why it cannot be taken.
    pub why: String,
}

impl SettingError {
    /// `key` given `value`, refused for `why`.
    pub fn new(key: &'static str, value: impl std::fmt::Display, why: impl Into<String>) -> Self {
        Self {
            key,
            value: Some(value.to_string()),
            why: why.into(),
        }
    }

    /// `key` refused for `why`, whatever its value (missing, or ruled out
    /// by another setting).
    pub fn because(key: &'static str, why: impl Into<String>) -> Self {
        Self {
            key,
            value: None,
            why: why.into(),
        }
    }

    /// The message with each key (the setting's and those `why` names in
    /// backticks) spelled by `spell`.
    #[must_use]
    pub fn spelled(&self, spell: impl Fn(&str) -> String) -> String {
        let mut out = spell(self.key);
        if let Some(v) = &self.value {
            out.push(' ');
            out.push_str(v);
        }
        out.push_str(": ");
        let mut parts = self.why.split('`');
        out.push_str(parts.next().unwrap_or(""));
        for (k, part) in parts.enumerate() {
            // Odd pieces are keys: between a pair of backticks.
            if k % 2 == 0 {
                out.push_str(&spell(part));
            } else {
                out.push_str(part);
            }
        }
        out
    }
}

/// `v` when it is a finite number > 0, else refused under `key` (`unit`
/// says what it measures).
pub fn positive(key: &'static str, v: f64, unit: &str) -> Result<f64, SettingError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(SettingError::new(
            key,
            v,
            format!("must be a finite number > 0 ({unit})"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_spelled_by_the_front_end_and_the_rest_kept() {
        let e = SettingError::new("loss_scale", 0, "is for `loss` huber or cauchy");
        assert_eq!(
            e.to_string(),
            "`loss_scale` 0: is for `loss` huber or cauchy"
        );
        let flag = |k: &str| format!("--{}", k.replace('_', "-"));
        assert_eq!(
            e.spelled(flag),
            "--loss-scale 0: is for --loss huber or cauchy"
        );
        let m = SettingError::because("loss_scale", "`loss` huber needs it");
        assert_eq!(m.spelled(str::to_string), "loss_scale: loss huber needs it");
        assert!(positive("noise", f64::NAN, "metres").is_err());
        assert_eq!(positive("noise", 0.5, "metres"), Ok(0.5));
    }
}
