//! Gate baselines that hold nothing usable used to make the gate pass (nothing compared, exit 0).
//! Now an unusable baseline is an input error before the first render, and a LOD or metric the
//! baseline lacks fails the gate.

use super::{assert_refused, scratch, write};
use crate::common::{lodeval, model};

fn config(dir: &std::path::Path, baseline: &str, ratios: &str) -> std::path::PathBuf {
    let mesh = model("bunny/bunny_odedstein_3k.obj");
    write(
        dir,
        "gate.toml",
        &format!(
            "out = \"out\"\nmetrics = [\"flip\"]\n[render]\nsize = 96\n[distance]\nenabled = false\n{baseline}\n[[asset]]\nname = \"bunny\"\nmesh = \"{}\"\ngenerate = {{ method = \"meshopt\", ratios = [{ratios}] }}\n",
            mesh.display()
        ),
    )
}

#[test]
fn an_unusable_baseline_is_an_input_error_before_rendering() {
    let tmp = scratch("baseline");
    let d = tmp.path();
    // A real summary to take rows and the header from.
    let cfg = config(d, "", "0.5");
    let r = lodeval(["eval".as_ref(), cfg.as_os_str()]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let summary = std::fs::read_to_string(d.join("out/summary.csv")).unwrap();
    let header = summary.lines().next().unwrap().to_string();
    let other_asset = summary.replace("\nbunny,", "\ndragon,");
    let nan = {
        let mut lines: Vec<String> = summary.lines().map(str::to_string).collect();
        let mut f: Vec<String> = lines[1].split(',').map(str::to_string).collect();
        f[5] = "NaN".into();
        lines[1] = f.join(",");
        lines.join("\n") + "\n"
    };
    std::fs::remove_dir_all(d.join("out")).unwrap();
    std::fs::create_dir_all(d.join("folder.csv")).unwrap();
    let cases: Vec<(&str, Option<String>, &[&str])> = vec![
        ("empty.csv", Some(String::new()), &["empty.csv", "no rows"]),
        (
            "header.csv",
            Some(format!("{header}\n")),
            &["header.csv", "no rows"],
        ),
        (
            "prose.csv",
            Some("this is\nnot a table\n".into()),
            &["prose.csv"],
        ),
        ("folder.csv", None, &["folder.csv", "not a regular file"]),
        (
            "other.csv",
            Some(other_asset),
            &["other.csv", "no rows for any asset", "dragon"],
        ),
        (
            "nan.csv",
            Some(nan),
            &["nan.csv", "line 2", "not a finite number"],
        ),
    ];
    for (name, text, words) in cases {
        if let Some(text) = text {
            write(d, name, &text);
        }
        let cfg = config(d, &format!("[gate]\nbaseline = \"{name}\""), "0.5");
        let r = lodeval(["eval".as_ref(), cfg.as_os_str()]);
        assert_refused(&r, name, words);
        assert!(!d.join("out").exists(), "{name}: rendered before refusing");
    }
    #[cfg(unix)]
    {
        let cfg = config(d, "[gate]\nbaseline = \"/dev/zero\"", "0.5");
        let r = lodeval(["eval".as_ref(), cfg.as_os_str()]);
        assert_refused(&r, "/dev/zero", &["/dev/zero", "not a regular file"]);
    }
}

#[test]
fn a_lod_the_baseline_lacks_fails_the_gate() {
    let tmp = scratch("baseline-missing");
    let d = tmp.path();
    let cfg = config(d, "", "0.5");
    assert_eq!(lodeval(["eval".as_ref(), cfg.as_os_str()]).code, 0);
    std::fs::copy(d.join("out/summary.csv"), d.join("base.csv")).unwrap();
    // The same config with a second LOD: the baseline has never seen it.
    let cfg = config(d, "[gate]\nbaseline = \"base.csv\"", "0.5, 0.25");
    let r = lodeval(["eval".as_ref(), cfg.as_os_str()]);
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert!(
        r.stderr
            .contains("bunny/meshopt-r25 baseline: the LOD is not in the baseline"),
        "{}",
        r.stderr
    );
    assert!(!r.stderr.contains("meshopt-r50 baseline"), "{}", r.stderr);
    let junit = std::fs::read_to_string(d.join("out/junit.xml")).unwrap();
    assert!(junit.contains("<failure"), "{junit}");
}
