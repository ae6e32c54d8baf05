//! The plan: a parsed config expanded into assets × LODs (with resolved paths, generator steps,
//! layered thresholds and engine switch distances) and split into shards.
//!
//! Decisions:
//! - A case is one (asset, LOD) pair, id `ASSET/LOD`. Shards split cases by a stable hash of the
//!   id (64-bit FNV-1a), so adding an asset moves no other case between shards. Every shard that
//!   has a case of an asset renders that asset's original itself (no shared state between
//!   machines).
//! - Generated LODs form a chain: each step is simplified from the previous one (as engines
//!   build LOD chains), ratios first in the given order, then error targets.

use std::path::{Path, PathBuf};

use super::config::{Config, ThresholdKey, Thresholds, config_dir, resolve};
use crate::error::{Error, Result};
use crate::simplify::{Goal, Method};

/// Where a LOD's mesh comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum LodSource {
    /// A file.
    File(PathBuf),
    /// Step `step` (0-based) of the asset's generated chain.
    Generated {
        /// The simplifier.
        method: Method,
        /// Position in the chain.
        step: usize,
        /// Ratio of the original's triangles or relative error.
        target: GenTarget,
    },
}

/// A generator step's target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GenTarget {
    /// Fraction of the original's triangle count.
    Ratio(f64),
    /// Error relative to the bounding-box diagonal.
    Error(f64),
    /// Viewing distance in metres (menzel-guthe).
    Distance(f64),
    /// Vertices of a remesh (qu-meyer).
    Vertices(usize),
}

impl GenTarget {
    /// The simplifier goal.
    pub fn goal(self) -> Goal {
        match self {
            GenTarget::Ratio(r) => Goal::Ratio(r),
            GenTarget::Error(e) => Goal::Error(e),
            GenTarget::Distance(d) => Goal::Distance(d),
            GenTarget::Vertices(v) => Goal::Vertices(v),
        }
    }
}

/// One resolved threshold: its value and where it was set.
#[derive(Debug, Clone, PartialEq)]
pub struct Limit {
    /// Threshold key (see [`Thresholds`]).
    pub name: &'static str,
    /// Its value.
    pub value: f64,
    /// Where it was set, e.g. `configs/ci.toml [thresholds]`.
    pub origin: String,
}

/// One LOD of an asset.
#[derive(Debug, Clone)]
pub struct LodPlan {
    /// Name in outputs.
    pub name: String,
    /// Mesh source.
    pub source: LodSource,
    /// The engine's switch distance, metres, if the config gives one.
    pub switch_m: Option<f64>,
    /// Resolved thresholds.
    pub limits: Vec<Limit>,
}

/// One asset.
#[derive(Debug, Clone)]
pub struct AssetPlan {
    /// Name in outputs.
    pub name: String,
    /// The original mesh.
    pub mesh: PathBuf,
    /// Metres per model unit.
    pub meters_per_unit: f64,
    /// Its LODs, in chain order.
    pub lods: Vec<LodPlan>,
}

/// Everything a run will do.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The parsed config.
    pub config: Config,
    /// The config file.
    pub config_path: PathBuf,
    /// The config text (kept so shard outputs can be merged without the file).
    pub config_text: String,
    /// Assets in config order.
    pub assets: Vec<AssetPlan>,
}

/// A case id: `ASSET/LOD`.
pub fn case_id(asset: &str, lod: &str) -> String {
    format!("{asset}/{lod}")
}

impl Plan {
    /// The files the plan reads, as written in it: the config, the gate's baseline, every
    /// original and LOD mesh (what an output folder must never hold among what it clears).
    pub fn input_files(&self) -> Vec<PathBuf> {
        let mut files = vec![self.config_path.clone()];
        if let Some(b) = &self.config.gate.baseline {
            files.push(resolve(&config_dir(&self.config_path), b));
        }
        for a in &self.assets {
            files.push(a.mesh.clone());
            files.extend(a.lods.iter().filter_map(|l| match &l.source {
                LodSource::File(p) => Some(p.clone()),
                LodSource::Generated { .. } => None,
            }));
        }
        files
    }

    /// Parse and expand a config file.
    pub fn load(config_path: &Path) -> Result<Plan> {
        let text = crate::io::read_input_text(
            config_path,
            "config",
            crate::limits::CONFIG_BYTES,
            "check the path",
        )?;
        let plan = Plan::from_text(text, config_path)?;
        plan.check_meshes()?;
        Ok(plan)
    }

    /// Every mesh the config names exists, before anything is loaded or rendered (a missing
    /// second asset used to fail after the first was done). The message gives the line and
    /// where the path led, relative to the config's folder. Not part of [`Plan::from_text`]:
    /// `merge` rebuilds plans of runs made on other machines.
    pub(crate) fn check_meshes(&self) -> Result<()> {
        let written = self.config.assets.iter().flat_map(|a| {
            std::iter::once((a, &a.mesh)).chain(a.lods.iter().map(move |l| (a, &l.mesh)))
        });
        let base = config_dir(&self.config_path);
        for (asset, mesh) in written {
            let resolved = resolve(&base, mesh);
            if crate::mesh::split_level(&resolved).0.exists() {
                continue;
            }
            let quoted = format!("\"{}\"", mesh.display());
            let problem = format!(
                "asset '{}': mesh {quoted} is not there ({}): paths in a config are relative to \
                 the config file's folder",
                asset.name.0,
                resolved.display()
            );
            let fix = "fix the path, relative to the config file";
            return Err(match self.config_text.find(&quoted) {
                Some(i) => Error::input_at(
                    &self.config_path,
                    crate::error::Location::Line(self.config_text[..i].matches('\n').count() + 1),
                    problem,
                    fix,
                ),
                None => Error::input(&self.config_path, problem, fix),
            });
        }
        Ok(())
    }

    /// Expand config text; `config_path` anchors relative paths.
    pub fn from_text(text: String, config_path: &Path) -> Result<Plan> {
        let config = Config::parse(&text, config_path)?;
        Plan::expand(config, text, config_path)
    }

    /// A plan from a config built as a value (see [`Config::new`]): checked as a file would
    /// be; `origin` names it in messages and anchors its relative paths. Its text (for the
    /// run's manifest) is the config written as TOML.
    pub fn from_config(config: Config, origin: &Path) -> Result<Plan> {
        let config = config.checked(origin)?;
        let text = config.to_toml()?;
        Plan::expand(config, text, origin)
    }

    /// Assets × LODs with their layered limits, from a checked config.
    fn expand(config: Config, text: String, config_path: &Path) -> Result<Plan> {
        let base = config_dir(config_path);
        let file = config_path.display().to_string();
        let global = layer(&config.thresholds, &format!("{file} [thresholds]"), &[]);
        let mut assets = Vec::new();
        for a in &config.assets {
            let asset_limits = layer(
                &a.thresholds,
                &format!("{file} asset '{}' thresholds", a.name.0),
                &global,
            );
            let names = config.lod_names(a);
            let mut lods = Vec::new();
            for (i, l) in a.lods.iter().enumerate() {
                lods.push(LodPlan {
                    name: names[i].0.clone(),
                    source: LodSource::File(resolve(&base, &l.mesh)),
                    switch_m: l.switch_m.map(|s| s.0),
                    limits: layer(
                        &l.thresholds,
                        &format!(
                            "{file} asset '{}' LOD '{}' thresholds",
                            a.name.0, names[i].0
                        ),
                        &asset_limits,
                    ),
                });
            }
            if let Some(g) = &a.generate {
                let targets = g
                    .ratios
                    .iter()
                    .map(|r| GenTarget::Ratio(r.0))
                    .chain(g.errors.iter().map(|e| GenTarget::Error(e.0)))
                    .chain(g.distances.iter().map(|d| GenTarget::Distance(d.0)))
                    .chain(g.vertices.iter().map(|&v| GenTarget::Vertices(v)));
                for (step, target) in targets.enumerate() {
                    lods.push(LodPlan {
                        name: names[a.lods.len() + step].0.clone(),
                        source: LodSource::Generated {
                            method: g.method,
                            step,
                            target,
                        },
                        switch_m: g.switch_m.get(step).map(|s| s.0),
                        limits: asset_limits.clone(),
                    });
                }
            }
            assets.push(AssetPlan {
                name: a.name.0.clone(),
                mesh: resolve(&base, &a.mesh),
                meters_per_unit: a.meters_per_unit.0,
                lods,
            });
        }
        let plan = Plan {
            config,
            config_path: config_path.to_path_buf(),
            config_text: text,
            assets,
        };
        plan.check_gate()?;
        Ok(plan)
    }

    /// The gate's checks that need no results, so that a config the gate cannot judge fails
    /// before the first render (not after all of them, without `junit.xml`): every threshold's
    /// metric is computed, and every `switch_m` has distances to be checked against.
    fn check_gate(&self) -> Result<()> {
        let computed = &self.config.metrics;
        for asset in &self.assets {
            for lod in &asset.lods {
                for limit in &lod.limits {
                    let family = ThresholdKey::of(limit.name).metric.family();
                    if !computed.contains(&family) {
                        return Err(Error::input(
                            &self.config_path,
                            format!(
                                "threshold {} (set in {}) needs the metric family '{}', which \
                                 the config does not compute",
                                limit.name,
                                limit.origin,
                                family.name()
                            ),
                            "add its family to `metrics` or remove the threshold",
                        ));
                    }
                }
                if lod.switch_m.is_some() && !self.config.distance.enabled {
                    return Err(Error::input(
                        &self.config_path,
                        format!(
                            "asset '{}' LOD '{}' has switch_m but distances are disabled",
                            asset.name, lod.name
                        ),
                        "set [distance] enabled = true or remove switch_m",
                    ));
                }
            }
        }
        if self.config.export.gltf != super::config::GltfExport::None
            && !self.config.distance.enabled
        {
            return Err(Error::input(
                &self.config_path,
                "[export] gltf takes its switch points from the measured distances, and                  [distance] is disabled",
                "set [distance] enabled = true, or remove [export]",
            ));
        }
        Ok(())
    }

    /// Every case id in plan order.
    pub fn case_ids(&self) -> Vec<String> {
        self.assets
            .iter()
            .flat_map(|a| a.lods.iter().map(|l| case_id(&a.name, &l.name)))
            .collect()
    }
}

/// Overlay `t` on `below`: fields set in `t` replace the same names.
fn layer(t: &Thresholds, origin: &str, below: &[Limit]) -> Vec<Limit> {
    let mut out: Vec<Limit> = below.to_vec();
    for (name, value) in t.entries() {
        let Some(value) = value else { continue };
        let limit = Limit {
            name,
            value,
            origin: origin.to_string(),
        };
        match out.iter_mut().find(|l| l.name == name) {
            Some(l) => *l = limit,
            None => out.push(limit),
        }
    }
    out
}

/// One shard of a run: `index` in `0..count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// 0-based shard index.
    pub index: u32,
    /// Number of shards.
    pub count: u32,
}

impl Shard {
    /// The whole run.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Parse `INDEX/COUNT` (0-based index).
    pub fn parse(text: &str) -> Result<Shard> {
        let bad = || {
            Error::Usage(format!(
                "--shard '{text}': use INDEX/COUNT with 0 ≤ INDEX < COUNT, e.g. 0/2"
            ))
        };
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count): (u32, u32) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// The shard named by the environment of common CI systems and Kubernetes indexed jobs:
    /// `TEST_SHARD_INDEX`/`TEST_TOTAL_SHARDS` (Bazel-style), `CI_NODE_INDEX`/`CI_NODE_TOTAL`
    /// (GitLab, 1-based index), `JOB_COMPLETION_INDEX` with `LODEVAL_SHARD_COUNT` (Kubernetes).
    pub fn from_env(get: impl Fn(&str) -> Option<String>) -> Result<Option<Shard>> {
        let pair = |i: &str, n: &str, one_based: bool| -> Result<Option<Shard>> {
            match (get(i), get(n)) {
                (Some(i), Some(n)) => {
                    let idx: u32 = i.trim().parse().map_err(|_| {
                        Error::Usage(format!("environment shard index '{i}' is not a number"))
                    })?;
                    let idx = if one_based {
                        idx.saturating_sub(1)
                    } else {
                        idx
                    };
                    Shard::parse(&format!("{idx}/{}", n.trim())).map(Some)
                }
                _ => Ok(None),
            }
        };
        if let Some(s) = pair("TEST_SHARD_INDEX", "TEST_TOTAL_SHARDS", false)? {
            return Ok(Some(s));
        }
        if let Some(s) = pair("CI_NODE_INDEX", "CI_NODE_TOTAL", true)? {
            return Ok(Some(s));
        }
        pair("JOB_COMPLETION_INDEX", "LODEVAL_SHARD_COUNT", false)
    }

    /// Whether this shard runs `case`.
    pub fn contains(&self, case: &str) -> bool {
        fnv1a(case.as_bytes()) % self.count as u64 == self.index as u64
    }
}

/// 64-bit FNV-1a, finished with MurmurHash3's fmix64: FNV's low bits alone are the parity of
/// the bytes' low bits, so `% 2` would put most ids into one shard.
fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h = bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    });
    h ^= h >> 33;
    h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
    h ^= h >> 33;
    h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    h ^ (h >> 33)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::config::{AssetConfig, LodConfig};

    #[test]
    fn thresholds_layer_and_remember_their_origin() {
        let text = r#"
[thresholds]
flip_mean = 0.1
psnr_min = 20.0
[[asset]]
name = "a"
mesh = "a.obj"
thresholds = { flip_mean = 0.05 }
lods = [{ mesh = "a1.obj", thresholds = { psnr_min = 30.0 } }, { mesh = "a2.obj" }]
"#;
        let p = Plan::from_text(text.into(), Path::new("c/x.toml")).unwrap();
        let l = &p.assets[0].lods;
        let get = |lod: &LodPlan, n: &str| {
            let x = lod.limits.iter().find(|l| l.name == n).unwrap();
            (x.value, x.origin.clone())
        };
        assert_eq!(get(&l[0], "flip_mean").0, 0.05);
        assert!(get(&l[0], "flip_mean").1.contains("asset 'a' thresholds"));
        assert_eq!(get(&l[0], "psnr_min").0, 30.0);
        assert!(get(&l[0], "psnr_min").1.contains("LOD 'lod1'"));
        assert_eq!(get(&l[1], "psnr_min").0, 20.0);
        assert!(get(&l[1], "psnr_min").1.contains("[thresholds]"));
        assert_eq!(p.assets[0].mesh, Path::new("c/a.obj"));
    }

    #[test]
    fn a_config_written_as_toml_reads_back_as_itself() {
        // Every shipped config, and one with thresholds, lights and generated LODs.
        let mut texts: Vec<(String, PathBuf)> = ["demo.toml", "ci.toml", "nightly.toml"]
            .iter()
            .map(|f| {
                let path = Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("configs")
                    .join(f);
                (std::fs::read_to_string(&path).unwrap(), path)
            })
            .collect();
        texts.push((
            r#"
metrics = ["flip", "psnr", "vdp"]
[thresholds]
flip_mean = 0.1
[render]
rig = "fibonacci:7"
tone_mapping = "aces"
lights = [{ kind = "directional", direction = [0.0, 1.0, 0.0], intensity = 0.5 }]
[[asset]]
name = "a"
mesh = "a.obj"
generate = { method = "meshopt", ratios = [0.5, 0.25], switch_m = [3.0, 6.0] }
lods = [{ mesh = "a1.obj", name = "x", thresholds = { psnr_min = 30.0 } }]
"#
            .into(),
            PathBuf::from("c/x.toml"),
        ));
        for (text, path) in texts {
            let config = Config::parse(&text, &path).unwrap();
            let written = config.to_toml().unwrap();
            let again = Config::parse(&written, &path).unwrap();
            assert_eq!(again.to_toml().unwrap(), written, "{}", path.display());
            let (a, b) = (
                Plan::from_text(text, &path).unwrap(),
                Plan::from_config(again, &path).unwrap(),
            );
            assert_eq!(a.case_ids(), b.case_ids());
            for (x, y) in a.assets.iter().zip(&b.assets) {
                assert_eq!((&x.mesh, x.meters_per_unit), (&y.mesh, y.meters_per_unit));
                for (l, m) in x.lods.iter().zip(&y.lods) {
                    assert_eq!(format!("{:?}", l.limits), format!("{:?}", m.limits));
                    assert_eq!(l.switch_m, m.switch_m);
                }
            }
        }
    }

    #[test]
    fn a_plan_built_as_a_value_takes_any_file_name_and_is_checked() {
        let weird = PathBuf::from(r#"C:\models\a "quoted" name.obj"#);
        let mut asset = AssetConfig::new("a", weird.clone()).unwrap();
        asset
            .lods
            .push(LodConfig::new("a-lod", weird.clone()).unwrap());
        let plan = Plan::from_config(Config::new(vec![asset]), Path::new("<test>")).unwrap();
        assert_eq!(plan.assets[0].mesh, weird);
        assert!(AssetConfig::new("a/b", weird.clone()).is_err());
        let mut bad = Config::new(vec![AssetConfig::new("a", weird).unwrap()]);
        bad.metrics.clear();
        let e = Plan::from_config(bad, Path::new("<test>"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("metrics is empty"), "{e}");
    }

    #[test]
    fn shards_partition_cases() {
        let ids: Vec<String> = (0..200)
            .map(|i| format!("asset{}/lod{}", i / 7, i % 7))
            .collect();
        for count in [1, 2, 3, 8] {
            let mut seen = 0;
            for index in 0..count {
                let s = Shard { index, count };
                seen += ids.iter().filter(|c| s.contains(c)).count();
            }
            assert_eq!(seen, ids.len());
        }
        // Both halves get a fair share (FNV's raw low bit would not).
        let half = Shard { index: 0, count: 2 };
        let n = ids.iter().filter(|c| half.contains(c)).count();
        assert!((70..=130).contains(&n), "{n} of 200 in shard 0/2");
        assert!(Shard::parse("2/2").is_err() && Shard::parse("x").is_err());
        assert_eq!(Shard::parse("1/3").unwrap(), Shard { index: 1, count: 3 });
        let env = |k: &str| match k {
            "CI_NODE_INDEX" => Some("2".to_string()),
            "CI_NODE_TOTAL" => Some("4".to_string()),
            _ => None,
        };
        assert_eq!(
            Shard::from_env(env).unwrap(),
            Some(Shard { index: 1, count: 4 })
        );
    }
}
