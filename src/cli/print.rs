//! Everything the CLI writes to stdout and stderr: values as text or JSON, the eval summary and
//! gate verdict, and the library's warnings. The library returns; this prints.

use std::io::Write;

use lodeval::Error;

/// Write a value to stdout as pretty JSON with a trailing newline.
pub(crate) fn emit_json<T: serde::Serialize>(value: &T) -> Result<(), Error> {
    lodeval::io::finite::check(value).map_err(|field| {
        Error::Internal(format!(
            "the JSON output has {field}, which is not a finite number"
        ))
    })?;
    let json = serde_json::to_string_pretty(value).map_err(|e| Error::Internal(e.to_string()))?;
    emit(&(json + "\n"))
}

/// Write to stdout; a closed pipe (e.g. `| head`) is not an error.
pub(crate) fn emit(text: &str) -> Result<(), Error> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        // Not a lodeval bug: the output went to a full device or a failing file.
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Error::input(
            std::path::Path::new("<standard output>"),
            format!("cannot write: {e}"),
            "free space on the device standard output goes to, or redirect it elsewhere",
        )),
        _ => Ok(()),
    }
}

/// Print an eval or merge outcome: the summary table on stdout, failures on stderr, exit 1 on
/// failure.
pub(crate) fn gate_result(outcome: &lodeval::eval::Outcome) -> Result<(), Error> {
    warnings(&outcome.warnings);
    emit(&lodeval::eval::summary_table(outcome))?;
    for f in &outcome.failures {
        note!("{}", f.message);
    }
    if outcome.failures.is_empty() {
        emit(&format!(
            "wrote {}; open {} in a browser\n",
            outcome.out_dir.display(),
            outcome.out_dir.join("report.html").display()
        ))
    } else {
        Err(Error::Regression(format!(
            "{} gate check(s) failed; details in {}",
            outcome.failures.len(),
            outcome.out_dir.join("report.html").display()
        )))
    }
}

/// Print warnings the library returned, one `warning:` line each, on stderr.
pub(crate) fn warnings(lines: &[String]) {
    for w in lines {
        note!("warning: {w}");
    }
}
