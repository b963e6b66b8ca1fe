//! Command-line values of the setting enums of the lower crates, which do
//! not know clap: each enum's names ([`Named`]) are the option's possible
//! values.

use clap::builder::{PossibleValuesParser, TypedValueParser};
use psa_sim::named::Named;

/// A parser of one of `T`'s variants, each written as its name; `--help`
/// and the error for an unknown value list the names.
pub fn choice<T: Named + Send + Sync>() -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(T::names()).map(|text| {
        *T::VARIANTS
            .iter()
            .find(|&&value| value.name() == text)
            .expect("clap admits only the possible values")
    })
}
