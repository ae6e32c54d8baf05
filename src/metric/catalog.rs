//! The catalogue of reported metrics: one entry per value lodeval writes (a `metric` in
//! `metrics.csv` and `summary.csv`, a result of `diff`), with its name, unit, the direction in
//! which it gets worse, the values it can take, its family (the `metrics` key of a config that
//! computes it) and how it is titled on a chart. Everything that names, orders, ranges, gates or
//! plots a metric — the scorer, the gate, the tables, the plots, the report, `diff` and `compare` —
//! reads it here. Adding a metric is a variant and an entry below, plus its module in this folder
//! (and, if a config should compute it, its family's arm in `eval/score.rs`).

use serde::{Deserialize, Serialize};

/// Metric families: what a config's `metrics` list names; each writes one or more [`Metric`]s.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MetricFamily {
    /// `flip` (mean), `flip_p95`, `flip_share`.
    Flip,
    /// `ssim`.
    Ssim,
    /// `msssim` (images ≥ 176 px per side).
    Msssim,
    /// `psnr`, `psnr_luminance` and `mse` (luminance).
    Psnr,
    /// `vdp` (detection probability) and `vdp_jnd`.
    Vdp,
}

/// One reported value. The serde name (snake case) is the name in CSV and JSON.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// ꟻLIP's mean error.
    Flip,
    /// The 95th percentile of the per-pixel ꟻLIP map.
    FlipP95,
    /// The share of pixels whose ꟻLIP exceeds a per-pixel level.
    FlipShare,
    /// SSIM on sRGB luma.
    Ssim,
    /// Multi-scale SSIM on sRGB luma.
    Msssim,
    /// PSNR of the 8-bit sRGB encodings over all three channels.
    Psnr,
    /// PSNR of linear Rec. 709 luminance (peak 1).
    PsnrLuminance,
    /// MSE of linear Rec. 709 luminance.
    Mse,
    /// The visible-difference predictor's detection probability.
    Vdp,
    /// The visible-difference predictor's difference in just-noticeable differences.
    VdpJnd,
}

/// Which way a metric gets worse.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Worse {
    /// A larger value is a larger difference (FLIP, MSE, the VDP).
    Higher,
    /// A smaller value is a larger difference (SSIM, MS-SSIM, PSNR).
    Lower,
}

/// A metric's entry in the catalogue.
#[derive(Debug, Clone, Copy)]
pub struct Entry {
    /// The metric.
    pub metric: Metric,
    /// Its name in CSV, JSON and file names.
    pub name: &'static str,
    /// One line on what it is, with its unit.
    pub what: &'static str,
    /// Its unit (`dB`, `JND`; empty where it has none).
    pub unit: &'static str,
    /// Which way it gets worse.
    pub worse: Worse,
    /// The smallest and largest value it can take.
    pub range: (f64, f64),
    /// The family that computes it.
    pub family: MetricFamily,
    /// A chart's axis title.
    pub title: &'static str,
    /// What its per-pixel map holds (larger is worse), for metrics that have one (a heat map, a
    /// share of pixels over a level, a worst pixel).
    pub map: Option<&'static str>,
}

const UNIT: (f64, f64) = (0.0, 1.0);

/// The catalogue, in display order (the order of `metrics.csv` and `summary.csv` rows).
pub const CATALOG: [Entry; 10] = [
    Entry {
        metric: Metric::Flip,
        name: "flip",
        what: "ꟻLIP mean error in [0, 1]",
        unit: "",
        worse: Worse::Higher,
        range: UNIT,
        family: MetricFamily::Flip,
        title: "FLIP (0 = identical)",
        map: Some("ꟻLIP error"),
    },
    Entry {
        metric: Metric::FlipP95,
        name: "flip_p95",
        what: "95th percentile of the per-pixel ꟻLIP map",
        unit: "",
        worse: Worse::Higher,
        range: UNIT,
        family: MetricFamily::Flip,
        title: "FLIP, 95th percentile of pixels",
        map: None,
    },
    Entry {
        metric: Metric::FlipShare,
        name: "flip_share",
        what: "Share of pixels whose ꟻLIP exceeds the per-pixel level",
        unit: "",
        worse: Worse::Higher,
        range: UNIT,
        family: MetricFamily::Flip,
        title: "share of pixels over the FLIP level",
        map: None,
    },
    Entry {
        metric: Metric::Ssim,
        name: "ssim",
        what: "SSIM on sRGB luma, in [−1, 1]",
        unit: "",
        worse: Worse::Lower,
        range: (-1.0, 1.0),
        family: MetricFamily::Ssim,
        title: "SSIM (1 = identical)",
        map: Some("1 − SSIM"),
    },
    Entry {
        metric: Metric::Msssim,
        name: "msssim",
        what: "Multi-scale SSIM on sRGB luma (images of at least 176×176)",
        unit: "",
        worse: Worse::Lower,
        range: (-1.0, 1.0),
        family: MetricFamily::Msssim,
        title: "MS-SSIM (1 = identical)",
        map: None,
    },
    Entry {
        metric: Metric::Psnr,
        name: "psnr",
        what: "PSNR of the 8-bit sRGB encodings, all three channels (as scikit-image, ffmpeg, \
               idiff), dB",
        unit: "dB",
        worse: Worse::Lower,
        range: (0.0, super::mse::PSNR_CEILING_DB),
        family: MetricFamily::Psnr,
        title: "PSNR (8-bit sRGB), dB (higher is closer)",
        map: None,
    },
    Entry {
        metric: Metric::PsnrLuminance,
        name: "psnr_luminance",
        what: "PSNR of linear luminance (peak 1), dB",
        unit: "dB",
        worse: Worse::Lower,
        range: (f64::NEG_INFINITY, super::mse::PSNR_CEILING_DB),
        family: MetricFamily::Psnr,
        title: "PSNR (linear luminance), dB (higher is closer)",
        map: None,
    },
    Entry {
        metric: Metric::Mse,
        name: "mse",
        what: "MSE of linear luminance",
        unit: "",
        worse: Worse::Higher,
        range: (0.0, f64::INFINITY),
        family: MetricFamily::Psnr,
        title: "MSE (linear luminance)",
        map: None,
    },
    Entry {
        metric: Metric::Vdp,
        name: "vdp",
        what: "The visible-difference predictor: detection probability in [0, 1] (and JND)",
        unit: "",
        worse: Worse::Higher,
        range: UNIT,
        family: MetricFamily::Vdp,
        title: "VDP detection probability",
        map: Some("detection probability"),
    },
    Entry {
        metric: Metric::VdpJnd,
        name: "vdp_jnd",
        what: "The visible-difference predictor's difference in just-noticeable differences",
        unit: "JND",
        worse: Worse::Higher,
        range: (0.0, f64::INFINITY),
        family: MetricFamily::Vdp,
        title: "VDP, JND",
        map: None,
    },
];

impl Metric {
    /// Every metric, in display order.
    pub const ALL: [Metric; 10] = {
        let mut all = [Metric::Flip; 10];
        let mut i = 0;
        while i < CATALOG.len() {
            all[i] = CATALOG[i].metric;
            i += 1;
        }
        all
    };

    /// The metric that leads where one is needed (a chart in the report, the order of the worst
    /// views): the first of these a run computed.
    pub const LEADING: [Metric; 5] = [
        Metric::Flip,
        Metric::Vdp,
        Metric::Ssim,
        Metric::Psnr,
        Metric::Msssim,
    ];

    /// The metrics `lodeval diff` computes, in its output order.
    pub const DIFF: [Metric; 7] = [
        Metric::Flip,
        Metric::Ssim,
        Metric::Msssim,
        Metric::Psnr,
        Metric::PsnrLuminance,
        Metric::Mse,
        Metric::Vdp,
    ];

    /// Its catalogue entry.
    pub fn entry(self) -> &'static Entry {
        &CATALOG[self.rank()]
    }

    /// Its place in display order.
    pub fn rank(self) -> usize {
        CATALOG
            .iter()
            .position(|e| e.metric == self)
            .expect("every metric has an entry")
    }

    /// Its name in CSV, JSON and file names.
    pub fn name(self) -> &'static str {
        self.entry().name
    }

    /// The metric of a name, if it is one.
    pub fn from_name(name: &str) -> Option<Metric> {
        CATALOG.iter().find(|e| e.name == name).map(|e| e.metric)
    }

    /// Whether a larger value means a larger difference.
    pub fn higher_is_worse(self) -> bool {
        self.entry().worse == Worse::Higher
    }

    /// The smallest and largest value it can take.
    pub fn range(self) -> (f64, f64) {
        self.entry().range
    }

    /// The family that computes it.
    pub fn family(self) -> MetricFamily {
        self.entry().family
    }

    /// Whether it has a per-pixel map.
    pub fn has_map(self) -> bool {
        self.entry().map.is_some()
    }

    /// What its per-pixel map holds (`1 − SSIM` for SSIM), where it has one.
    pub fn map_label(self) -> Option<&'static str> {
        self.entry().map
    }

    /// `Err` with the reason when `limit` (a gate's value, named `flag`) could never fail, or
    /// would always fail, since no value of the metric lies beyond it.
    pub fn check_limit(self, flag: &str, limit: f64) -> Result<(), String> {
        let (lo, hi) = self.range();
        let (never, always) = if self.higher_is_worse() {
            (limit >= hi, limit < lo)
        } else {
            (limit <= lo, limit > hi)
        };
        let span = format!("{} lies in [{lo}, {hi}]", self.name());
        if never {
            return Err(format!(
                "{flag} {limit}: {span}, so no result is ever worse than {limit} and the gate \
                 could never fail; give a limit inside the range"
            ));
        }
        if always {
            return Err(format!(
                "{flag} {limit}: {span}, so every result is worse than {limit} and the gate \
                 would always fail; give a limit inside the range"
            ));
        }
        Ok(())
    }
}

impl MetricFamily {
    /// Its name in a config's `metrics` list.
    pub fn name(self) -> &'static str {
        match self {
            MetricFamily::Flip => "flip",
            MetricFamily::Ssim => "ssim",
            MetricFamily::Msssim => "msssim",
            MetricFamily::Psnr => "psnr",
            MetricFamily::Vdp => "vdp",
        }
    }

    /// The metrics it writes, in display order.
    pub fn metrics(self) -> impl Iterator<Item = Metric> {
        Metric::ALL.into_iter().filter(move |m| m.family() == self)
    }
}

impl std::fmt::Display for Metric {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_the_serde_names_and_round_trip() {
        for m in Metric::ALL {
            let json = serde_json::to_string(&m).unwrap();
            assert_eq!(json, format!("\"{}\"", m.name()));
            assert_eq!(Metric::from_name(m.name()), Some(m));
            assert_eq!(m.entry().metric, m);
        }
        assert_eq!(Metric::from_name("flip_mean"), None);
    }

    #[test]
    fn display_order_is_the_catalogue_order_and_every_family_writes_a_metric() {
        let ranks: Vec<usize> = Metric::ALL.iter().map(|m| m.rank()).collect();
        assert_eq!(ranks, (0..10).collect::<Vec<_>>());
        for f in [
            MetricFamily::Flip,
            MetricFamily::Ssim,
            MetricFamily::Msssim,
            MetricFamily::Psnr,
            MetricFamily::Vdp,
        ] {
            assert!(f.metrics().count() >= 1, "{f:?}");
        }
    }

    #[test]
    fn a_limit_outside_the_range_is_refused_either_way() {
        assert!(Metric::Flip.check_limit("--fail", 1.0).is_err());
        assert!(Metric::Flip.check_limit("--fail", -0.1).is_err());
        assert!(Metric::Flip.check_limit("--fail", 0.05).is_ok());
        assert!(Metric::Ssim.check_limit("--fail", -1.0).is_err());
        assert!(Metric::Ssim.check_limit("--fail", 1.5).is_err());
        assert!(Metric::Psnr.check_limit("--fail", 30.0).is_ok());
    }
}
