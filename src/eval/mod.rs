//! Batch evaluation: configs → plan → renders and scores → the output files the README lists → the
//! gate's exit code. One stage per file:
//!
//! - `config.rs` — the TOML schema, defaults, and exit-2 messages with file and line;
//! - `plan.rs` — assets × LODs, layered thresholds, shards;
//! - `run.rs` — the render-and-score loop, heat maps, contact sheets;
//! - `score.rs` — the metric families per view pair;
//! - `distance.rs` — imperceptibility distances and engine LOD parameters;
//! - `tables.rs` — `metrics.csv`, `summary.csv`, `distances.csv`, `lods.csv`;
//! - `gate.rs` — thresholds, switch distances, baseline comparison;
//! - `junit.rs`, `report.rs` — `junit.xml`, `report.html`;
//! - `plots.rs` — `plots/*.png` (error against triangles, switch distances);
//! - `golden.rs` — golden-image compare and bless;
//! - `manifest.rs` — `shard.json`: the cases a run covered and the files it wrote (hashes);
//! - `out.rs` — the output folder: what a run owns there, checked and cleared before it starts.
//!
//! This file joins them: [`eval`] runs a config (or one shard of it) and writes every output,
//! [`merge`] joins shard outputs into exactly the files one machine would have written. Every
//! run also writes `shard.json` (the config text, the shard and its cases) so a merge needs
//! nothing but the folders.

#[doc(hidden)] // a stage of `eval::run`, public for tests; start from `Plan` and `run`
pub mod assets;
#[doc(hidden)] // a stage of `eval::run`, public for tests; start from `Plan` and `run`
pub mod cache;
pub mod compare;
pub mod config;
pub mod distance;
#[doc(hidden)] // a stage of `eval::run`, public for tests; start from `Plan` and `run`
pub mod export;
pub mod gate;
pub mod golden;
#[doc(hidden)] // a stage of `eval::run`, public for tests; start from `Plan` and `run`
pub mod junit;
mod manifest;
#[doc(hidden)] // a stage of `eval::run`, public for tests; start from `Plan` and `run`
pub mod out;
pub mod plan;
#[doc(hidden)] // a stage of `eval::run`, public for tests; start from `Plan` and `run`
pub mod plots;
#[doc(hidden)] // a stage of `eval::run`, public for tests; start from `Plan` and `run`
pub mod report;
#[doc(hidden)] // a stage of `eval::run`, public for tests; start from `Plan` and `run`
pub mod run;
#[doc(hidden)] // a stage of `eval::run`, public for tests; start from `Plan` and `run`
pub mod score;
pub mod tables;

use std::path::{Path, PathBuf};

use manifest::Manifest;

pub use gate::Failure;
pub use plan::{Plan, Shard};
pub use run::RunOptions;
pub use tables::Results;

use crate::error::{Error, Result};

/// What a run or a merge produced.
#[derive(Debug)]
pub struct Outcome {
    /// Output folder.
    pub out_dir: PathBuf,
    /// The tables.
    pub results: Results,
    /// Gate failures (empty: pass).
    pub failures: Vec<Failure>,
    /// The plan.
    pub plan: Plan,
    /// What the user should know besides the gate (why `--backend auto` rendered on the CPU).
    pub warnings: Vec<String>,
}

/// Run a config (one shard of it) and write every output.
pub fn eval(
    config: &Path,
    options: &RunOptions,
    progress: &dyn crate::progress::Progress,
) -> Result<Outcome> {
    let plan = Plan::load(config)?;
    gate::check_baseline(&plan)?;
    let out = run::run(plan, options, progress)?;
    let inputs = manifest::record_inputs(&out.inputs, &io_parent(&out.plan.config_path))?;
    let manifest = Manifest {
        config_path: out.plan.config_path.clone(),
        config_text: out.plan.config_text.clone(),
        shard: format!("{}/{}", options.shard.index, options.shard.count),
        cases: out
            .plan
            .case_ids()
            .into_iter()
            .filter(|c| options.shard.contains(c))
            .collect(),
        files: Vec::new(),
        inputs,
    };
    let mut outcome = finish(out.plan, out.dir, out.results, &manifest)?;
    outcome.warnings = out.warnings;
    Ok(outcome)
}

/// Write the tables, gate, JUnit, report and manifest; returns the outcome.
fn finish(plan: Plan, dir: out::RunDir, results: Results, manifest: &Manifest) -> Result<Outcome> {
    let out_dir = dir.path().to_path_buf();
    results.write_csvs(&out_dir)?;
    let failures = gate::check(&plan, &results)?;
    crate::io::write_atomic(
        &out_dir.join("junit.xml"),
        junit::render(&plan, &results, &failures)?.as_bytes(),
    )?;
    crate::io::write_atomic(
        &out_dir.join("report.html"),
        report::render(&plan, &results, &failures).as_bytes(),
    )?;
    plots::write(&plan, &results, &out_dir)?;
    let manifest = Manifest {
        files: manifest::record(&out_dir)?,
        ..manifest.clone()
    };
    let json = serde_json::to_string_pretty(&manifest)
        .map_err(|e| Error::Internal(format!("shard.json: {e}")))?;
    crate::io::write_atomic(&out_dir.join("shard.json"), json.as_bytes())?;
    dir.seal()?;
    Ok(Outcome {
        out_dir,
        results,
        failures,
        plan,
        warnings: Vec::new(),
    })
}

/// Join the outputs of shard runs into `out`: fails (exit 2) when the shards ran different
/// configs, a case ran twice, a case of the plan is missing, a shard's files differ from what it
/// recorded in `shard.json`, or `out` is (or holds, or lies in) a shard folder. Everything is
/// checked before anything is written, so a failed merge leaves no half-made folder.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<Outcome> {
    if dirs.is_empty() {
        return Err(Error::Usage("merge needs at least one shard folder".into()));
    }
    // The shards: manifests, each folder's files against its manifest, the tables.
    let manifests = read_manifests(dirs)?;
    let first = &manifests[0];
    for (m, d) in manifests.iter().zip(dirs).skip(1) {
        manifest::check_same_inputs(first, &dirs[0], m, d)?;
        if m.config_text != first.config_text {
            return Err(Error::input(
                &d.join("shard.json"),
                format!(
                    "ran a different config than {} did",
                    dirs[0].join("shard.json").display()
                ),
                "merge only shards of one run of one config",
            ));
        }
    }
    let plan = Plan::from_text(first.config_text.clone(), &first.config_path)?;
    let mut seen: std::collections::BTreeMap<&str, &Path> = Default::default();
    for (m, d) in manifests.iter().zip(dirs) {
        for c in &m.cases {
            if let Some(other) = seen.insert(c, d) {
                return Err(Error::input(
                    &d.join("shard.json"),
                    format!("case {c} is also in {}", other.display()),
                    "merge each shard once; shards of one run never share a case",
                ));
            }
        }
    }
    let all = plan.case_ids();
    if let Some(missing) = all.iter().find(|c| !seen.contains_key(c.as_str())) {
        return Err(Error::Usage(format!(
            "case {missing} is in no shard folder: run its shard (and give all {} shards)",
            first.shard.split('/').nth(1).unwrap_or("?")
        )));
    }
    let mut results = Results::default();
    for (d, m) in dirs.iter().zip(&manifests) {
        let r = Results::read_csvs(d)?;
        check_shard_tables(d, m, &r)?;
        results.rows.extend(r.rows);
        results.lods.extend(r.lods);
        results.distances.extend(r.distances);
    }
    results.sort(&all);
    // The output folder: not a shard folder, nor inside or around one; then cleared.
    for d in dirs {
        if same_or_nested(out, d) {
            return Err(Error::Usage(format!(
                "--out {} is, holds or lies inside the shard folder {}: the merge would overwrite \
                 its input; merge into a new folder",
                out.display(),
                d.display()
            )));
        }
    }
    let dir = out::prepare(out, out::EVAL, &[])?;
    for d in dirs {
        for sub in manifest::IMAGE_DIRS {
            copy_tree(&d.join(sub), &out.join(sub))?;
        }
    }
    let manifest = Manifest {
        config_path: first.config_path.clone(),
        config_text: first.config_text.clone(),
        shard: "0/1".into(),
        cases: all,
        files: Vec::new(),
        inputs: manifests
            .iter()
            .flat_map(|m| m.inputs.iter().cloned())
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect(),
    };
    finish(plan, dir, results, &manifest)
}

/// Each shard folder's manifest, with the folder's files checked against it.
fn read_manifests(dirs: &[PathBuf]) -> Result<Vec<Manifest>> {
    let mut manifests = Vec::new();
    for d in dirs {
        let path = d.join("shard.json");
        let text = crate::io::read_input_text(
            &path,
            "shard manifest",
            crate::limits::CONFIG_BYTES,
            "give folders written by `lodeval eval --shard`",
        )?;
        let m: Manifest = serde_json::from_str(&text).map_err(|e| {
            Error::input(
                &path,
                format!("is not an lodeval shard manifest: {e}"),
                "give folders written by `lodeval eval --shard`",
            )
        })?;
        manifest::verify(d, &m)?;
        manifests.push(m);
    }
    Ok(manifests)
}

/// A shard's tables hold its own cases only, and every case it ran has its rows.
fn check_shard_tables(d: &Path, m: &Manifest, r: &Results) -> Result<()> {
    // Every row belongs to one of the shard's own cases.
    let cases = r.rows.iter().map(|x| (&x.asset, &x.lod));
    let cases = cases.chain(r.lods.iter().map(|x| (&x.asset, &x.lod)));
    let cases = cases.chain(r.distances.iter().map(|x| (&x.asset, &x.lod)));
    for (asset, lod) in cases {
        let id = plan::case_id(asset, lod);
        if !m.cases.contains(&id) {
            return Err(Error::input(
                &d.join("shard.json"),
                format!("the shard's tables hold case {id}, which it did not run"),
                manifest::FIX,
            ));
        }
    }
    // And every case the shard ran has its rows.
    for c in &m.cases {
        let has = |a: &String, l: &String| plan::case_id(a, l) == *c;
        let lods = r.lods.iter().filter(|x| has(&x.asset, &x.lod)).count();
        if lods != 1 || !r.rows.iter().any(|x| has(&x.asset, &x.lod)) {
            return Err(Error::input(
                &d.join("shard.json"),
                format!(
                    "case {c} has {lods} rows in lods.csv and its metrics rows are {}",
                    if r.rows.iter().any(|x| has(&x.asset, &x.lod)) {
                        "there"
                    } else {
                        "missing"
                    }
                ),
                manifest::FIX,
            ));
        }
    }
    Ok(())
}

/// Whether `a` and `b` are the same folder or one lies inside the other ([`crate::io::target`]:
/// links and `missing/..` do not hide it).
fn same_or_nested(a: &Path, b: &Path) -> bool {
    let (a, b) = (crate::io::target(a), crate::io::target(b));
    a.starts_with(&b) || b.starts_with(&a)
}

/// The folder a config lies in (where its relative paths start).
fn io_parent(config: &Path) -> PathBuf {
    crate::io::parent_dir(config)
}

fn copy_tree(from: &Path, to: &Path) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(from) else {
        return Ok(());
    };
    let mut entries: Vec<_> = entries.filter_map(|e| e.ok()).collect();
    entries.sort_by_key(|e| e.file_name());
    for e in entries {
        let (src, dst) = (e.path(), to.join(e.file_name()));
        if src.is_dir() {
            copy_tree(&src, &dst)?;
        } else {
            let bytes = crate::io::read_input(
                &src,
                "shard image",
                crate::limits::IMAGE_BYTES,
                "check the shard folder",
            )?;
            crate::io::write_atomic(&dst, &bytes)?;
        }
    }
    Ok(())
}

/// The table `eval` prints: one line per LOD. What the user came for leads — below what
/// on-screen size and beyond what distance the LOD cannot be told from the original — then the
/// scores at the render size, labelled with it (a close-up, where every LOD is visible).
pub fn summary_table(outcome: &Outcome) -> String {
    let r = &outcome.results;
    let size = outcome.plan.config.render.size.0;
    let (vdp, jnd) = (format!("vdp@{size}px"), format!("jnd@{size}px"));
    let mut s = format!(
        "{:<12} {:<16} {:>9} {:>7} {:>22} {:>22} {:>8} {:>8} {:>8} {:>10} {:>10}  gate\n",
        "asset",
        "lod",
        "triangles",
        "ratio",
        "imperceptible_below_px",
        "imperceptible_beyond_m",
        "flip",
        "flip_max",
        "psnr_min",
        vdp,
        jnd
    );
    let fmt = |v: Option<f64>, d: usize| match v {
        Some(x) if x.is_finite() => format!("{x:.d$}"),
        Some(_) => "inf".into(),
        None => "-".into(),
    };
    for l in &r.lods {
        let hl = r.headline(&l.asset, &l.lod);
        let dist = hl.distance.as_ref().map(tables::DistanceRow::distance_text);
        let px = hl.distance.as_ref().map(tables::DistanceRow::diameter_text);
        let failed = outcome
            .failures
            .iter()
            .any(|f| f.asset == l.asset && f.lod == l.lod);
        s.push_str(&format!(
            "{:<12} {:<16} {:>9} {:>7.4} {:>22} {:>22} {:>8} {:>8} {:>8} {:>10} {:>10}  {}\n",
            l.asset,
            l.lod,
            l.triangles,
            l.triangles as f64 / l.original_triangles.max(1) as f64,
            px.unwrap_or_else(|| "-".into()),
            dist.unwrap_or_else(|| "-".into()),
            fmt(hl.flip_mean, 4),
            fmt(hl.flip_worst, 4),
            fmt(hl.psnr_worst, 2),
            fmt(hl.vdp_worst, 3),
            fmt(hl.vdp_jnd_worst, 2),
            if failed { "FAIL" } else { "pass" }
        ));
    }
    s.push_str(&format!(
        "imperceptible_below_px / imperceptible_beyond_m: the LOD cannot be told from the original \
         (VDP) while the object is smaller on screen than this (its bounding sphere's diameter, \
         display pixels) / farther than this (metres); ≥/≤ where the search only bounds it \
         (distances.csv: diameter_px, imperceptible_beyond_m) · the rest at the {size} px \
         close-up render, where every LOD is visible: flip: mean ꟻLIP over views (0 same … 1), \
         flip_max: worst view · psnr_min: worst view, dB (8-bit sRGB) · {vdp}: detection \
         probability, {jnd}: JND (1 = threshold), worst view\n"
    ));
    s
}
