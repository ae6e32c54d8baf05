//! The one CSV writer and reader: every table lodeval writes goes through [`write_rows`], every one
//! it reads back through [`read_rows`].
//!
//! Decisions: a header given explicitly is written even for an empty table (eval's tables are
//! stable schemas that downstream tools read by column name); without one, the header comes from
//! the row type's field names (serde), as for the paper experiments' tables. Files are written
//! atomically ([`super::write_atomic`]). A row that does not parse names the file and its line.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Location, Result};

/// Write `rows` as CSV to `path`, atomically: with `header` first when given (also for no rows),
/// else with serde's header from the field names.
pub fn write_rows<T: Serialize>(path: &Path, header: Option<&[&str]>, rows: &[T]) -> Result<()> {
    let mut w = ::csv::WriterBuilder::new()
        .has_headers(header.is_none())
        .from_writer(Vec::new());
    let fail =
        |e: &dyn std::fmt::Display| Error::Internal(format!("writing {}: {e}", path.display()));
    if let Some(h) = header {
        w.write_record(h).map_err(|e| fail(&e))?;
    }
    for (i, r) in rows.iter().enumerate() {
        // No NaN or infinity reaches a table (the output guard, `finite.rs`).
        super::finite::check(r).map_err(|field| {
            fail(&format!(
                "row {} has {field}, which is not a finite number",
                i + 1
            ))
        })?;
        w.serialize(r).map_err(|e| fail(&e))?;
    }
    let bytes = w.into_inner().map_err(|e| fail(&e))?;
    super::write_atomic(path, &bytes)
}

/// Read a CSV with a header into rows; `fix` tells the user what file was expected. Only a
/// regular file of at most [`crate::limits::TABLE_BYTES`] is read.
pub fn read_rows<T: for<'de> Deserialize<'de>>(path: &Path, fix: &str) -> Result<Vec<T>> {
    // Only a regular file of bounded size: a folder, a FIFO or /dev/zero would block or read
    // without end.
    super::check_input(path, "table", crate::limits::TABLE_BYTES, fix)?;
    let mut r = ::csv::Reader::from_path(path)
        .map_err(|e| Error::input(path, format!("cannot read: {e}"), fix))?;
    r.deserialize()
        .enumerate()
        .map(|(i, row)| {
            row.map_err(|e| {
                Error::input_at(
                    path,
                    Location::Line(i + 2),
                    format!("is not an lodeval table: {e}"),
                    fix,
                )
            })
        })
        .collect()
}
