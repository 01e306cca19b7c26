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
