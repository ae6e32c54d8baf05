//! How the library reports progress on long work without printing: it calls a [`Progress`] the
//! caller gives, and the caller draws (the CLI: a bar on a terminal, a line every few seconds in a
//! CI log; tests and other library users: [`Silent`]).
//!
//! Decision: one stage at a time (`start` … `finish`), counted in steps of a named unit, or
//! uncounted (a spinner). Implementations must be cheap to call from inside loops and safe to
//! call from worker threads, and must never change what the library computes.

/// Receives progress reports. Every method has a do-nothing default.
pub trait Progress: Sync {
    /// A stage begins: `total` steps of `unit` (`None`: not counted), described by `message`.
    fn start(&self, _total: Option<u64>, _unit: &str, _message: &str) {}
    /// The stage's description changes (what it is working on now).
    fn set_message(&self, _message: &str) {}
    /// `steps` more steps are done.
    fn advance(&self, _steps: u64) {}
    /// `done` steps are done in all.
    fn set_position(&self, _done: u64) {}
    /// The stage is over.
    fn finish(&self) {}
}

/// Reports nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Progress for Silent {}
