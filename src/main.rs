//! The `lodeval` binary: check the CPU, parse the command line, run it, and map the outcome to an
//! exit code (0 ok · 1 regression or golden mismatch · 2 bad input or usage · 3 internal error ·
//! 130 interrupted by a signal).
//! Everything else is in `cli/` (the command line) and the library.

mod cli;

use std::process::ExitCode;
use std::sync::Mutex;

use clap::Parser;
use lodeval::Error;

/// The message of the last panic, kept so a crash is reported once, as an internal error.
static PANIC_MESSAGE: Mutex<Option<String>> = Mutex::new(None);

fn main() -> ExitCode {
    // Before anything else: a build for newer CPUs than this one would die of an illegal
    // instruction somewhere later.
    let missing = lodeval::cpu::missing();
    if !missing.is_empty() {
        let e = Error::Usage(format!(
            "this lodeval was built for x86-64-v3 CPUs and this CPU lacks {}; build it for this \
             CPU with RUSTFLAGS=\"\" cargo build --release (see .cargo/config.toml)",
            missing.join(", ")
        ));
        report(&e);
        return ExitCode::from(e.exit_code());
    }
    let cli = cli::Cli::parse();
    // SIGINT, SIGTERM, SIGHUP: remove temporaries, lock files and what the run wrote into its
    // output folder, so nothing half-written looks complete; then exit 130.
    let _ = ctrlc::set_handler(|| {
        lodeval::io::interrupted();
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr().lock(),
            "error: interrupted; removed this run's temporary and partial outputs"
        );
        std::process::exit(130);
    });
    std::panic::set_hook(Box::new(|info| {
        if let Ok(mut slot) = PANIC_MESSAGE.lock() {
            *slot = Some(info.to_string());
        }
    }));
    let outcome = std::panic::catch_unwind(move || cli::run(cli)).unwrap_or_else(|_| {
        let msg = PANIC_MESSAGE
            .lock()
            .ok()
            .and_then(|m| m.clone())
            .unwrap_or_default();
        Err(Error::Internal(msg))
    });
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            report(&e);
            ExitCode::from(e.exit_code())
        }
    }
}

/// The one error line on standard error; a full or closed stderr cannot turn it into a panic.
fn report(e: &Error) {
    use std::io::Write as _;
    let _ = writeln!(std::io::stderr().lock(), "error: {e}");
}
