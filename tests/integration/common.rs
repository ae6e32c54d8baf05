//! Helpers shared by the integration tests: running the CLI and locating data.

use std::path::{Path, PathBuf};
use std::process::Command;

/// What one CLI run produced.
#[derive(Debug)]
pub struct Run {
    pub code: i32,
    pub stdout: String,
    pub stderr: String,
}

/// Run the `lodeval` binary built for this test run with `args`.
pub fn lodeval<I, S>(args: I) -> Run
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    lodeval_env(args, &[])
}

/// [`lodeval`] with environment variables set (`Some`) or removed (`None`).
pub fn lodeval_env<I, S>(args: I, env: &[(&str, Option<&str>)]) -> Run
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_lodeval"));
    cmd.args(args);
    for (key, value) in env {
        match value {
            Some(v) => cmd.env(key, v),
            None => cmd.env_remove(key),
        };
    }
    output(cmd)
}

/// [`lodeval`] run in the folder `dir` (relative paths in `args` resolve there).
pub fn lodeval_in<I, S>(dir: &Path, args: I) -> Run
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_lodeval"));
    cmd.args(args).current_dir(dir);
    output(cmd)
}

/// Run `cmd` (without a backtrace variable from the test's environment) to completion.
fn output(mut cmd: Command) -> Run {
    let out = cmd
        .env_remove("RUST_BACKTRACE")
        .output()
        .expect("the lodeval binary runs");
    Run {
        code: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// `lodeval simplify SRC -o OUT` with `args` after them.
pub fn simplify(src: &Path, out: &Path, args: &[&str]) -> Run {
    let mut all = vec![
        "simplify",
        src.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    lodeval(all)
}

/// The repository root.
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A shipped reference model.
pub fn model(rel: &str) -> PathBuf {
    root().join("reference/models").join(rel)
}

/// The shared model collection beside the checkout, if present.
pub fn shared_models() -> Option<PathBuf> {
    let p = root().join("../shared/models");
    p.join("MANIFEST.md").exists().then_some(p)
}

/// How many times longer than planned a test waits before it calls a run a hang:
/// `LODEVAL_TEST_TIME_SCALE` (default 1; raise it on a slow or shared machine).
pub fn time_scale() -> f64 {
    std::env::var("LODEVAL_TEST_TIME_SCALE")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s >= 1.0)
        .unwrap_or(1.0)
}

/// A wall-clock limit for work planned to take at most `seconds` on an idle machine: 5× that,
/// times [`time_scale`]. For waits that cannot watch a process's CPU time.
pub fn hang_limit(seconds: u64) -> std::time::Duration {
    std::time::Duration::from_secs_f64(5.0 * seconds as f64 * time_scale())
}

/// CPU seconds (user + system, all threads) process `pid` has used, from `/proc/PID/stat`
/// (fields 14 and 15, in clock ticks of 1/100 s on Linux); `None` where there is no `/proc`.
fn cpu_seconds(pid: u32) -> Option<f64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) is in parentheses and may hold spaces: count from after it.
    let fields: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
    let ticks: f64 = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// As [`lodeval`], but a hang fails the test (the child is killed) instead of stalling the suite
/// until CI's limit, and a slow machine does not. `seconds` is what the run may take on an idle
/// machine; the watchdog judges progress, not wall time: the child may use `seconds` of CPU per
/// core (a busy loop that never ends runs out of it however loaded the machine is), and a child
/// that uses no CPU (a deadlock) is stopped by the wall-clock [`hang_limit`]. Both scale with
/// [`time_scale`].
#[track_caller]
pub fn lodeval_within<I, S>(seconds: u64, args: I) -> Run
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    use std::io::Read;
    use std::process::Stdio;
    use std::time::{Duration, Instant};

    let args: Vec<std::ffi::OsString> = args.into_iter().map(|a| a.as_ref().into()).collect();
    let mut child = Command::new(env!("CARGO_BIN_EXE_lodeval"))
        .args(&args)
        .env_remove("RUST_BACKTRACE")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the lodeval binary runs");
    let drain = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            String::from_utf8_lossy(&bytes).into_owned()
        })
    };
    let stdout = drain(Box::new(child.stdout.take().unwrap()));
    let stderr = drain(Box::new(child.stderr.take().unwrap()));
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as f64;
    let cpu_budget = seconds as f64 * cores * time_scale();
    let deadline = Instant::now() + hang_limit(seconds);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        let used = cpu_seconds(child.id());
        let why = if used.is_some_and(|c| c > cpu_budget) {
            Some(format!("used more than {cpu_budget:.0} s of CPU"))
        } else if Instant::now() > deadline {
            Some(format!("did not finish within {:?}", hang_limit(seconds)))
        } else {
            None
        };
        if let Some(why) = why {
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "lodeval {args:?} {why} (a hang; set LODEVAL_TEST_TIME_SCALE on a slow machine)"
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    Run {
        code: status.code().unwrap_or(-1),
        stdout: stdout.join().unwrap(),
        stderr: stderr.join().unwrap(),
    }
}

/// Every file under `dir` (relative path → bytes).
pub fn files(dir: &Path) -> std::collections::BTreeMap<PathBuf, Vec<u8>> {
    let mut out = std::collections::BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(
                    p.strip_prefix(dir).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    out
}

#[test]
fn the_hang_watchdog_sees_cpu_time_where_there_is_proc() {
    // `lodeval_within` judges a run by the CPU it used, so a loaded machine cannot fail it; that
    // needs /proc's clock to move with work done.
    let Some(before) = cpu_seconds(std::process::id()) else {
        return; // no /proc (not Linux): the wall-clock limit alone applies
    };
    // Work until the clock moves 0.1 s (on a loaded machine that takes longer than 0.1 s of
    // wall time), giving up after 20 s.
    let start = std::time::Instant::now();
    let mut x = 0u64;
    let mut after = before;
    while after - before < 0.1 && start.elapsed() < std::time::Duration::from_secs(20) {
        for _ in 0..1_000_000 {
            x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
        }
        after = cpu_seconds(std::process::id()).unwrap();
    }
    assert!(after - before >= 0.1, "{before} → {after}");
    assert!(hang_limit(20) >= std::time::Duration::from_secs(100));
}
