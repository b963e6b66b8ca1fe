//! CSV files as tables of columns: each column's name, what it holds, and
//! how one row's value is written. The header, every row and the column
//! list in `docs/file-formats.md` come from the same table, so a column is
//! added in one place (and a test fails until the docs list it).

/// One column of a CSV file whose rows are `T`s.
pub struct Column<T> {
    /// Its name in the header.
    pub name: &'static str,
    /// What it holds, as `docs/file-formats.md` lists it.
    pub doc: &'static str,
    /// The field of one row, as written (see [`csv_field`] for text).
    pub value: fn(&T) -> String,
}

/// The header line of `columns`, without a line break.
pub fn header<T>(columns: &[Column<T>]) -> String {
    columns.iter().map(|c| c.name).collect::<Vec<_>>().join(",")
}

/// The line of `item` under `columns`, without a line break.
pub fn row<T>(columns: &[Column<T>], item: &T) -> String {
    columns.iter().map(|c| (c.value)(item)).collect::<Vec<_>>().join(",")
}

/// `columns` as the Markdown table `docs/file-formats.md` lists them in.
pub fn markdown<T>(columns: &[Column<T>]) -> String {
    let mut table = String::from("| column | meaning |\n|---|---|\n");
    for column in columns {
        table.push_str(&format!("| `{}` | {} |\n", column.name, column.doc));
    }
    table
}

/// `text` as one CSV field: quoted when it holds a comma, quote or line break.
pub fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_with_commas_or_quotes_are_quoted() {
        assert_eq!(csv_field("abc123-dirty"), "abc123-dirty");
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
    }

    #[test]
    fn docs_file_formats_lists_every_column_of_records_and_runs_csv() {
        let docs = include_str!("../../../docs/file-formats.md");
        for (file, table) in [
            (crate::RunFiles::RECORDS, markdown(&crate::run::RECORD_COLUMNS)),
            ("runs.csv", markdown(&crate::results::runs_table::RUN_COLUMNS)),
        ] {
            assert!(
                docs.contains(&table),
                "docs/file-formats.md does not list the columns of {file} as they are; its table must read:\n{table}"
            );
        }
    }
}
