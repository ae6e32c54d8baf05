//! Messages that misled: a mesh path in a config was said to be "resolved relative to the current
//! directory" (it is relative to the config), and a missing second asset failed only after the
//! first was rendered; standard output on a full device was exit 3, "a lodeval bug", and
//! standard error on one a panic. (A LOD simplified to nothing is in `numbers`, glTF accessors
//! past their views in `gltf`.)
#![cfg(unix)]

use std::process::{Command, Stdio};

use super::{assert_refused, scratch, write};
use crate::common::{lodeval_within, model};

#[test]
fn a_missing_mesh_in_a_config_names_the_line_and_the_config_folder() {
    let tmp = scratch("messages-config");
    let d = tmp.path();
    std::fs::create_dir(d.join("configs")).unwrap();
    let spot = model("spot/spot_mtl.obj");
    let cfg = write(
        &d.join("configs"),
        "two.toml",
        &format!(
            "out = \"out\"\n[[asset]]\nname = \"spot\"\nmesh = \"{}\"\ngenerate = {{ method = \"meshopt\", ratios = [0.5] }}\n\
             [[asset]]\nname = \"gone\"\nmesh = \"models/gone.obj\"\ngenerate = {{ method = \"meshopt\", ratios = [0.5] }}\n",
            spot.display()
        ),
    );
    let r = lodeval_within(60, ["eval".as_ref(), cfg.as_os_str()]);
    assert_refused(
        &r,
        "missing mesh",
        &[
            "two.toml",
            "line 8",
            "models/gone.obj",
            "configs/models/gone.obj",
            "relative to the config file's folder",
        ],
    );
    assert!(!r.stderr.contains("current directory"), "{}", r.stderr);
    // Refused before the first asset was rendered: no output folder at all.
    assert!(!d.join("configs/out").exists());
}

/// Run lodeval with stdout and/or stderr sent to `/dev/full`; returns the exit code.
fn to_full_device(args: &[&str], stdout_full: bool, stderr_full: bool) -> (i32, String) {
    let full = || {
        std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap()
    };
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_lodeval"));
    cmd.args(args).stdin(Stdio::null());
    cmd.stdout(if stdout_full {
        Stdio::from(full())
    } else {
        Stdio::null()
    });
    cmd.stderr(if stderr_full {
        Stdio::from(full())
    } else {
        Stdio::piped()
    });
    let out = cmd.output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_full_device_for_output_is_not_a_bug_and_not_a_panic() {
    let spot = model("spot/spot_mtl.obj");
    let spot = spot.to_str().unwrap();
    // stdout full: exit 2 with a message about standard output (was exit 3, "a lodeval bug").
    let (code, err) = to_full_device(&["info", spot], true, false);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("<standard output>") && err.contains("No space left"),
        "{err}"
    );
    assert!(!err.contains("bug") && !err.contains("panicked"), "{err}");
    let (code, err) = to_full_device(&["info", spot, "--json"], true, false);
    assert_eq!(code, 2, "{err}");
    // stderr full: the error still decides the exit code (was a panic, exit 101 or 134).
    let (code, _) = to_full_device(&["info", "/nonexistent/x.obj"], false, true);
    assert_eq!(code, 2);
    let (code, _) = to_full_device(&["info", "/nonexistent/x.obj"], true, true);
    assert_eq!(code, 2);
    // A warning to a full stderr does not stop a run that otherwise succeeds.
    let (code, _) = to_full_device(&["info", spot], false, true);
    assert_eq!(code, 0);
}
