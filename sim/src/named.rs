//! Closed enumerations: every enum a user names by a word (a backend, a
//! SIMD level, a preset, a report format) derives the list of its variants
//! ([`strum::VariantArray`]), their names ([`strum::IntoStaticStr`],
//! [`strum::Display`]) and its parser ([`strum::EnumString`]), so that a
//! new variant is listed, named and read everywhere without a line written
//! by hand. [`Named`] adds what the derives leave out: what a value is
//! called in messages, and the error for an unknown name, listing the
//! names; its enum's parser gives it with
//! `#[strum(parse_err_ty = String, parse_err_fn = Self::unknown)]`.

use strum::VariantArray;

/// An enumeration read and written by its variants' names (see the module).
pub trait Named: VariantArray + Copy + Into<&'static str> + 'static {
    /// What a value is called in messages ("backend", "SIMD level").
    const WHAT: &'static str;

    /// The variant's name.
    fn name(self) -> &'static str {
        self.into()
    }

    /// Every variant's name, in the order of the variants.
    fn names() -> Vec<&'static str> {
        Self::VARIANTS.iter().map(|&v| v.into()).collect()
    }

    /// The error for `name`, which no variant has: it names the value and
    /// lists the names.
    fn unknown(name: &str) -> String {
        format!(
            "unknown {} {name:?} (expected one of {})",
            Self::WHAT,
            Self::names().join(", ")
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numeric::SimdLevel;
    use crate::physics::{BackendKind, PlaneConstraint, Stepper};

    /// The names of earlier builds, which result files and command lines
    /// hold: a new variant adds its name, none changes.
    #[test]
    fn the_names_are_those_of_earlier_builds() {
        assert_eq!(SimdLevel::names(), ["portable", "avx2", "avx512"]);
        assert_eq!(BackendKind::names(), ["ode", "native", "rapier"]);
        assert_eq!(Stepper::names(), ["exact", "quick"]);
        assert_eq!(PlaneConstraint::names(), ["none", "plane2d_joint"]);
    }

    /// A configuration file and a command line spell a value alike: each
    /// name is the one serde writes.
    #[test]
    fn each_name_is_the_configurations_spelling() {
        fn spelt<T: Named + serde::Serialize>() {
            for &value in T::VARIANTS {
                assert_eq!(serde_json::to_value(value).unwrap(), value.name(), "{}", T::WHAT);
            }
        }
        spelt::<SimdLevel>();
        spelt::<BackendKind>();
        spelt::<Stepper>();
        spelt::<PlaneConstraint>();
    }

    #[test]
    fn every_name_reads_back_and_an_unknown_one_is_named() {
        for &level in SimdLevel::VARIANTS {
            assert_eq!(level.name().parse::<SimdLevel>(), Ok(level));
            assert_eq!(level.to_string(), level.name());
        }
        for &backend in BackendKind::VARIANTS {
            assert_eq!(backend.name().parse::<BackendKind>(), Ok(backend));
        }
        assert_eq!(
            "bullet".parse::<BackendKind>(),
            Err("unknown backend \"bullet\" (expected one of ode, native, rapier)".to_string())
        );
    }
}
