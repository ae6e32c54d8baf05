//! `junit.xml` for CI systems (through `quick-junit`): one test suite per asset, one test case per
//! LOD, failing with every gate message for that LOD. No timestamps or durations, so the file is
//! byte-identical across runs and thread counts.

use quick_junit::{NonSuccessKind, Report, TestCase, TestCaseStatus, TestSuite};

use super::gate::Failure;
use super::plan::Plan;
use super::tables::Results;
use crate::error::{Error, Result};

/// The JUnit XML text for a run.
pub fn render(plan: &Plan, results: &Results, failures: &[Failure]) -> Result<String> {
    let mut report = Report::new("lodeval");
    for asset in &plan.assets {
        let mut suite = TestSuite::new(asset.name.as_str());
        for lod in &asset.lods {
            let Some(info) = results
                .lods
                .iter()
                .find(|l| l.asset == asset.name && l.lod == lod.name)
            else {
                continue;
            };
            let mine: Vec<&Failure> = failures
                .iter()
                .filter(|f| f.asset == asset.name && f.lod == lod.name)
                .collect();
            let status = if mine.is_empty() {
                TestCaseStatus::success()
            } else {
                let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
                s.set_message(format!("{} check(s) failed", mine.len()));
                s.set_type("lodeval.gate");
                s.set_description(
                    mine.iter()
                        .map(|f| f.message.as_str())
                        .collect::<Vec<_>>()
                        .join("\n"),
                );
                s
            };
            let mut case = TestCase::new(lod.name.as_str(), status);
            case.set_classname(format!("lodeval.{}", asset.name));
            case.add_property(("triangles", info.triangles.to_string().as_str()));
            suite.add_test_case(case);
        }
        if !suite.test_cases.is_empty() {
            report.add_test_suite(suite);
        }
    }
    report
        .to_string()
        .map_err(|e| Error::Internal(format!("writing junit.xml: {e}")))
}
