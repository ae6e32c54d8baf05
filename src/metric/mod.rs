//! The perceptual difference stack. Colour conversions live in `color.rs`; the metrics themselves
//! arrive with the metric-stack issue.

pub mod color;
