//! A small reader for the numeric CSV tables the subcommands take on stdin.
//!
//! Format: the first non-blank line is a header of column names; each later line is
//! one row with as many comma-separated fields as the header. Fields and names are
//! trimmed of surrounding whitespace; `\r\n` line ends are accepted; blank lines and
//! lines starting with `#` are skipped. There is no quoting: fields are plain values.
//! Columns may come in any order. Every error names the line (1-based, counting every
//! line of the input) and, for a field, its column and value, and is a
//! [`CliError::input`] (exit code 2).
//!
//! ```text
//! let table = CsvTable::parse(text, &["thickness_nm", "angle_deg"], &["n_film"])?;
//! for row in table.rows() {
//!     let d = row.number("thickness_nm")?;
//!     let n = row.number_or("n_film", 1.33)?;
//! }
//! ```

use crate::error::CliError;

/// A parsed table: its columns and rows, validated against the expected column names.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvTable {
    columns: Vec<String>,
    rows: Vec<(usize, Vec<String>)>,
}

/// One data row of a [`CsvTable`].
#[derive(Debug, Clone, Copy)]
pub struct CsvRow<'a> {
    table: &'a CsvTable,
    line: usize,
    fields: &'a [String],
}

impl CsvTable {
    /// Parses `text`, whose header must name every column in `required`, may name those in
    /// `optional`, and nothing else; no column may appear twice.
    ///
    /// # Guarantees
    /// Every row has exactly one field per column.
    pub fn parse(text: &str, required: &[&str], optional: &[&str]) -> Result<CsvTable, CliError> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, line)| (i + 1, line.trim()))
            .filter(|(_, line)| !line.is_empty() && !line.starts_with('#'));
        let expected = || {
            required
                .iter()
                .chain(optional)
                .copied()
                .collect::<Vec<_>>()
                .join(",")
        };
        let Some((header_line, header)) = lines.next() else {
            return Err(CliError::input(format!(
                "empty input: expected a CSV header with columns {}",
                expected()
            )));
        };
        let columns = parse_header(header_line, header, required, optional)?;
        let mut rows = Vec::new();
        for (line, text) in lines {
            let fields: Vec<String> = text.split(',').map(|f| f.trim().to_owned()).collect();
            if fields.len() != columns.len() {
                return Err(CliError::input(format!(
                    "line {line}: {} fields, but the header (line {header_line}) has {} columns ({})",
                    fields.len(),
                    columns.len(),
                    columns.join(",")
                )));
            }
            rows.push((line, fields));
        }
        Ok(CsvTable { columns, rows })
    }

    /// Whether the header names `column`.
    pub fn has_column(&self, column: &str) -> bool {
        self.column_index(column).is_some()
    }

    /// The data rows in input order.
    pub fn rows(&self) -> impl ExactSizeIterator<Item = CsvRow<'_>> {
        self.rows.iter().map(|(line, fields)| CsvRow {
            table: self,
            line: *line,
            fields,
        })
    }

    fn column_index(&self, column: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == column)
    }
}

fn parse_header(
    line: usize,
    header: &str,
    required: &[&str],
    optional: &[&str],
) -> Result<Vec<String>, CliError> {
    let columns: Vec<String> = header.split(',').map(|c| c.trim().to_owned()).collect();
    let allowed = || {
        required
            .iter()
            .chain(optional)
            .copied()
            .collect::<Vec<_>>()
            .join(", ")
    };
    for (i, column) in columns.iter().enumerate() {
        if !required.contains(&column.as_str()) && !optional.contains(&column.as_str()) {
            return Err(CliError::input(format!(
                "line {line}: unknown column '{column}' (allowed: {})",
                allowed()
            )));
        }
        if columns[..i].contains(column) {
            return Err(CliError::input(format!(
                "line {line}: column '{column}' appears twice"
            )));
        }
    }
    let missing: Vec<&str> = required
        .iter()
        .copied()
        .filter(|r| !columns.iter().any(|c| c == r))
        .collect();
    if !missing.is_empty() {
        return Err(CliError::input(format!(
            "line {line}: missing column(s) {} in header '{header}'",
            missing.join(", ")
        )));
    }
    Ok(columns)
}

impl<'a> CsvRow<'a> {
    /// The 1-based line number of this row in the input.
    pub fn line(&self) -> usize {
        self.line
    }

    /// The raw field of `column`, or `None` if the header does not name it.
    pub fn get(&self, column: &str) -> Option<&'a str> {
        let index = self.table.column_index(column)?;
        Some(self.fields[index].as_str())
    }

    /// The field of `column` as a finite number; an error names the line, column and value.
    ///
    /// A column the header lacks is reported as missing (pass required columns here, or use
    /// [`CsvRow::number_or`] for optional ones).
    pub fn number(&self, column: &str) -> Result<f64, CliError> {
        let field = self
            .get(column)
            .ok_or_else(|| CliError::input(format!("line {}: no column '{column}'", self.line)))?;
        parse_finite(field).ok_or_else(|| self.bad(column, field, "is not a finite number"))
    }

    /// The field of `column` as a finite number, or `default` if the header does not name it.
    pub fn number_or(&self, column: &str, default: f64) -> Result<f64, CliError> {
        if self.table.has_column(column) {
            self.number(column)
        } else {
            Ok(default)
        }
    }

    /// An input error about this row's `column`, quoting `value`: "line L, column C: 'V' <what>".
    pub fn bad(&self, column: &str, value: &str, what: &str) -> CliError {
        CliError::input(format!(
            "line {}, column {column}: '{value}' {what}",
            self.line
        ))
    }
}

/// A finite f64, or `None` (also for `inf`/`NaN`, which `f64::from_str` would accept).
fn parse_finite(field: &str) -> Option<f64> {
    field.parse::<f64>().ok().filter(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn message(result: Result<CsvTable, CliError>) -> String {
        result.unwrap_err().to_string()
    }

    #[test]
    fn columns_in_any_order_with_optional_absent() {
        let text = "# comment\n\n b , a \r\n2,1\n\n4, 3\n";
        let table = CsvTable::parse(text, &["a", "b"], &["c"]).unwrap();
        assert!(!table.has_column("c"));
        let rows: Vec<(usize, f64, f64, f64)> = table
            .rows()
            .map(|r| {
                (
                    r.line(),
                    r.number("a").unwrap(),
                    r.number("b").unwrap(),
                    r.number_or("c", 9.0).unwrap(),
                )
            })
            .collect();
        assert_eq!(rows, [(4, 1.0, 2.0, 9.0), (6, 3.0, 4.0, 9.0)]);
    }

    #[test]
    fn header_errors_name_the_column() {
        assert!(message(CsvTable::parse("a,x\n", &["a"], &[])).contains("unknown column 'x'"));
        assert!(message(CsvTable::parse("a,a\n", &["a"], &[])).contains("'a' appears twice"));
        assert!(message(CsvTable::parse("a\n", &["a", "b"], &[])).contains("missing column(s) b"));
        assert!(message(CsvTable::parse(" \n", &["a"], &[])).contains("empty input"));
    }

    #[test]
    fn field_errors_name_line_column_and_value() {
        let err = message(CsvTable::parse("a,b\n1,2\n3\n", &["a", "b"], &[]));
        assert!(err.starts_with("line 3: 1 fields"), "{err}");
        let table = CsvTable::parse("a\n1\nabc\ninf\n", &["a"], &[]).unwrap();
        let errors: Vec<String> = table
            .rows()
            .filter_map(|r| r.number("a").err())
            .map(|e| e.to_string())
            .collect();
        assert_eq!(
            errors,
            [
                "line 3, column a: 'abc' is not a finite number",
                "line 4, column a: 'inf' is not a finite number"
            ]
        );
        assert_eq!(CliError::input("x").exit_code(), 2);
    }
}
