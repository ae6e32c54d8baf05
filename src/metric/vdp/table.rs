//! Reading the calibration datasets' CSV tables: a bounded read, the exact header, and every
//! number parsed, finite and in its range, or one message naming the file, the line, the value
//! and how to get a good copy.

use std::path::Path;

use crate::error::{Error, Location, Result};

/// Largest table read.
const MAX_TABLE_BYTES: u64 = 4 << 20;

/// One data row: its line in the file and its fields.
#[derive(Debug, Clone)]
pub(crate) struct Row {
    pub(crate) line: usize,
    pub(crate) fields: Vec<String>,
}

/// A dataset table: the file and its rows after the header.
#[derive(Debug, Clone)]
pub(crate) struct Table<'a> {
    path: &'a Path,
    fix: &'a str,
    pub(crate) rows: Vec<Row>,
}

impl<'a> Table<'a> {
    /// Read `path`, whose header must be exactly `header`; `fix` says how to get a good copy.
    pub(crate) fn read(path: &'a Path, header: &[&str], fix: &'a str) -> Result<Table<'a>> {
        let bytes = crate::io::read_input(path, "dataset table", MAX_TABLE_BYTES, fix)?;
        let mut reader = csv::ReaderBuilder::new().from_reader(bytes.as_slice());
        let found: Vec<String> = reader
            .headers()
            .map_err(|e| Error::input(path, format!("cannot read the header: {e}"), fix))?
            .iter()
            .map(str::to_string)
            .collect();
        if found != header {
            return Err(Error::input_at(
                path,
                Location::Line(1),
                format!("the header is {found:?}, not {}", header.join(",")),
                fix,
            ));
        }
        let mut rows = Vec::new();
        for (i, record) in reader.records().enumerate() {
            let line = i + 2;
            let record = record.map_err(|e| {
                Error::input_at(
                    path,
                    Location::Line(line),
                    format!("unreadable row: {e}"),
                    fix,
                )
            })?;
            if record.len() != header.len() {
                return Err(Error::input_at(
                    path,
                    Location::Line(line),
                    format!("{} fields instead of {}", record.len(), header.len()),
                    fix,
                ));
            }
            rows.push(Row {
                line,
                fields: record.iter().map(|f| f.trim().to_string()).collect(),
            });
        }
        if rows.is_empty() {
            return Err(Error::input(path, "the table has no rows", fix));
        }
        Ok(Table { path, fix, rows })
    }

    /// Field `k` of `row` as a number in [lo, hi].
    pub(crate) fn number(&self, row: &Row, k: usize, what: &str, lo: f64, hi: f64) -> Result<f64> {
        row.fields[k]
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && (lo..=hi).contains(v))
            .ok_or_else(|| {
                Error::input_at(
                    self.path,
                    Location::Line(row.line),
                    format!(
                        "{what} '{}' is not a number in [{lo}, {hi}]",
                        crate::error::quote(&row.fields[k])
                    ),
                    self.fix,
                )
            })
    }

    /// An error about `row`.
    pub(crate) fn error(&self, row: &Row, problem: String) -> Error {
        Error::input_at(self.path, Location::Line(row.line), problem, self.fix)
    }
}
