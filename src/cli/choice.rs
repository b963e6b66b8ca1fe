//! Command-line values of the setting enums of the lower crates, which do
//! not know clap: each enum's names are the option's possible values.

use clap::builder::{PossibleValuesParser, TypedValueParser};

/// A parser of one of `all`, each written as its `name`; `--help` and the
/// error for an unknown value list the names.
pub fn choice<T: Copy + Send + Sync + 'static>(
    all: &'static [T],
    name: fn(T) -> &'static str,
) -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(all.iter().map(|&value| name(value))).map(move |text| {
        *all.iter()
            .find(|&&value| name(value) == text)
            .expect("clap admits only the possible values")
    })
}
