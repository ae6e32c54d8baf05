//! `lodeval bench`: one file per benchmark; each returns rows the CLI prints as JSON or Markdown.
//! Reporting only: no test asserts on a time.

pub mod menzel_guthe;
pub mod metrics;
pub mod optimize;
pub mod raster;
pub mod simplify;
pub mod williams;

pub use menzel_guthe::*;
pub use metrics::*;
pub use optimize::*;
pub use raster::*;
pub use simplify::*;
pub use williams::*;

/// Peak resident set size of this process in MiB (Linux `VmHWM`), if known.
pub fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}
