//! `lodeval simplify MESH -o OUT.obj`: a LOD or a chain by any method, and Williams et al.'s
//! experiment (`--experiment`).

use std::path::PathBuf;

use clap::Args;
use lodeval::Error;
use lodeval::raster::Shading;
use lodeval::scene::Rig;
use lodeval::simplify::Method;
use lodeval::simplify::williams::Criterion;

use super::args::{LookArgs, count, parse_rig, parse_shading};
use super::print::{emit, emit_json};
use super::progress::Reporter;

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval simplify reference/models/bunny/stanford-bunny.obj -o bunny.obj --ratio 0.25\n  lodeval simplify spot.obj -o spot.obj --method menzel-guthe --distance 5\n\nExit codes: 0 written · 2 bad input or usage · 3 internal error"
)]
pub(crate) struct SimplifyArgs {
    /// The mesh to simplify.
    #[arg(required_unless_present = "experiment")]
    pub(crate) mesh: Option<PathBuf>,
    /// Output .obj (with --chain: files STEM-rXX.obj beside it).
    #[arg(short, long, required_unless_present = "experiment")]
    pub(crate) out: Option<PathBuf>,
    /// Run a paper's evaluation from its config: configs/papers/williams2003.toml (Williams et al.
    /// 2003) or configs/papers/menzel-guthe2010.toml (Menzel & Guthe 2010).
    #[arg(long, conflicts_with_all = ["mesh", "out"])]
    pub(crate) experiment: Option<PathBuf>,
    /// qem (our edge collapse, Garland–Heckbert quadrics), cluster (Rossignac–Borrel), meshopt,
    /// meshopt-update (meshoptimizer moving vertices and attributes, as qem does), or williams
    /// (Williams et al. 2003: perceptual, view-dependent, to a --budget).
    #[arg(long, value_enum, default_value_t = Method::Qem)]
    pub(crate) method: Method,
    /// williams: triangle budget.
    #[arg(long, conflicts_with_all = ["ratio", "triangles", "error", "chain", "distance"])]
    pub(crate) budget: Option<usize>,
    /// williams and menzel-guthe: the LOD is imperceptible from this viewing distance on, in
    /// metres (the display and viewer of the default viewing conditions; --meters-per-unit
    /// scales the model).
    #[arg(long, conflicts_with_all = ["ratio", "triangles", "error", "chain"])]
    pub(crate) distance: Option<f64>,
    /// menzel-guthe: metres per model unit (what --distance is measured against).
    #[arg(long, default_value_t = 1.0)]
    pub(crate) meters_per_unit: f64,
    /// williams: the camera, as EX,EY,EZ (looking at the model's centre, default field of view) or
    /// EX,EY,EZ,TX,TY,TZ. Default: view 0 of the default rig at the default framing.
    #[arg(long, value_delimiter = ',', num_args = 1, conflicts_with_all = ["view", "all_views"])]
    pub(crate) camera: Vec<f32>,
    /// williams: use view K of --rig.
    #[arg(long, conflicts_with = "all_views")]
    pub(crate) view: Option<usize>,
    /// williams: one static LOD for every view of --rig (each node keyed by its worst view).
    #[arg(long)]
    pub(crate) all_views: bool,
    /// williams: view rig for --view and --all-views.
    #[arg(long, default_value = "dodecahedron", value_parser = parse_rig)]
    pub(crate) rig: Rig,
    /// The shading a `.glb`/`.gltf` chain's switch points are measured with (auto: pbr for
    /// metallic–roughness materials, gouraud otherwise), and for williams the shading the LOD is
    /// for (gouraud, phong, normal-mapped, unlit; auto means gouraud).
    #[arg(long, default_value = "auto", value_parser = parse_shading)]
    pub(crate) shading: Shading,
    #[command(flatten)]
    pub(crate) look: LookArgs,
    /// williams: perceptual (default), object-space, screen-space or silhouette-10.
    #[arg(long, value_enum)]
    pub(crate) criterion: Option<Criterion>,
    /// williams: image size the views are rendered at (pixels; default 512).
    #[arg(long, value_parser = count::<u32>(&lodeval::limits::IMAGE_SIDE))]
    pub(crate) size: Option<u32>,
    /// Target ratio of the input's triangles.
    #[arg(long, conflicts_with_all = ["triangles", "error", "chain"])]
    pub(crate) ratio: Option<f64>,
    /// Target triangle count: the LOD has at most this many triangles (unless the mesh
    /// cannot be simplified that far).
    #[arg(long, conflicts_with_all = ["error", "chain"])]
    pub(crate) triangles: Option<usize>,
    /// Target error relative to the bounding-box diagonal (qem, meshopt).
    #[arg(long, conflicts_with = "chain")]
    pub(crate) error: Option<f64>,
    /// A chain of ratios, e.g. 0.5,0.25,0.1.
    #[arg(long, value_delimiter = ',')]
    pub(crate) chain: Vec<f64>,
    /// Print JSON.
    #[arg(long)]
    pub(crate) json: bool,
}

/// Run `simplify`.
pub(crate) fn run(a: SimplifyArgs, quiet: bool) -> Result<(), Error> {
    if let Some(config) = &a.experiment {
        return experiment(config, quiet);
    }
    if a.method == Method::Williams {
        return williams(&a);
    }
    // Flags of Williams et al. that another method would ignore: said, not silently dropped.
    let williams_only: Vec<&str> = [
        ("--camera", !a.camera.is_empty()),
        ("--view", a.view.is_some()),
        ("--all-views", a.all_views),
        ("--criterion", a.criterion.is_some()),
        ("--size", a.size.is_some()),
    ]
    .into_iter()
    .filter_map(|(flag, given)| given.then_some(flag))
    .collect();
    if !williams_only.is_empty() {
        super::print::warnings(&[format!(
            "{} apply to --method williams only; they do nothing with {}",
            williams_only.join(", "),
            a.method.name()
        )]);
    }
    use lodeval::simplify::Goal;
    let method = a.method;
    if method != Method::MenzelGuthe && a.distance.is_some() {
        return Err(Error::Usage(
            "--distance is for --method williams or menzel-guthe".into(),
        ));
    }
    let (flag, goals): (&str, Vec<Goal>) = if let Some(d) = a.distance {
        ("--distance", vec![Goal::Distance(d)])
    } else if !a.chain.is_empty() {
        ("--chain", a.chain.iter().map(|&r| Goal::Ratio(r)).collect())
    } else if let Some(r) = a.ratio {
        ("--ratio", vec![Goal::Ratio(r)])
    } else if let Some(t) = a.triangles {
        ("--triangles", vec![Goal::Triangles(t.max(1))])
    } else if let Some(e) = a.error {
        ("--error", vec![Goal::Error(e)])
    } else {
        return Err(Error::Usage(
            "give --ratio R, --triangles N, --error E, --chain R1,R2,... or (menzel-guthe) \
         --distance METRES"
                .into(),
        ));
    };
    // The library's checks, before the mesh is read; the mesh's triangle count is checked
    // once it is.
    lodeval::simplify::goals::check(method, &goals, None)
        .map_err(|why| Error::Usage(format!("{flag}: {why}")))?;
    let mut job = lodeval::app::SimplifyJob::new(
        a.mesh.expect("clap requires it"),
        a.out.expect("clap requires it"),
        method,
        goals.clone(),
    );
    job.chain = !a.chain.is_empty();
    job.meters_per_unit = a.meters_per_unit;
    job.look = a.look.look(a.shading);
    let report = lodeval::app::simplify(&job, &Reporter::new(quiet))?;
    super::print::warnings(&report.warnings);
    let rows = report.rows;
    warn_short_of_goals(&rows, &goals, method.name());
    if a.json {
        return emit_json(&rows);
    }
    let mut text = String::new();
    for r in &rows {
        let error = match &r.menzel_guthe {
            Some(mg) => format!(
                "imperceptible from {:.3} m ({} collapses; run: {} applied, {} perception tests, \
                 {} + {} postponed, {} Hausdorff tests)",
                mg.distance_m,
                mg.collapses,
                mg.run.applied,
                mg.run.perception_tests,
                mg.run.postponed_perceptual,
                mg.run.postponed_geometric,
                mg.run.hausdorff_tests
            ),
            None => format!(
                "simplifier error {}",
                r.simplifier_error
                    .map_or_else(|| "-".to_string(), |e| format!("{e:.3e}"))
            ),
        };
        text.push_str(&format!(
            "{}  {} triangles ({:.4} of the input), {error}\n",
            r.file.display(),
            r.triangles,
            r.ratio,
        ));
        if let Some(s) = &r.switch {
            text.push_str(&switch_line(s));
        }
    }
    emit(&text)
}

/// Where a chain level takes over, as the engines see it.
fn switch_line(s: &lodeval::app::SwitchPoint) -> String {
    let written = format!("MSFT_screencoverage {:.6}", s.screen_coverage);
    match &s.measured {
        Some(m) => format!(
            "    switches in below {} px on screen ({} m away; Unity {:.4}, Unreal {:.4}; \
             {written}) by {}\n",
            m.diameter_text(),
            m.distance_text(),
            m.screen_height_fraction,
            m.unreal_screen_size,
            m.criterion
        ),
        None => format!("    not measured; {written}\n"),
    }
}

/// `simplify --experiment CONFIG`: Menzel & Guthe's or Williams et al.'s reproduction.
fn experiment(config: &std::path::Path, quiet: bool) -> Result<(), Error> {
    if lodeval::experiments::paper_of(config)? == "menzel-guthe2010" {
        let report = lodeval::experiments::menzel_guthe2010::run(config, &mut |line| {
            if !quiet {
                note!("{line}")
            }
        })?;
        return emit(&format!(
            "{} Table 2 rows, {} Figure 1 materials, {} study LODs written\n",
            report.table2.len(),
            report.figure1.len(),
            report.study.len()
        ));
    }
    let rows = lodeval::experiments::williams2003::run(config, &mut |line| note!("{line}"))?;
    note!("{} curve points written", rows.len());
    Ok(())
}

/// `simplify --method williams`.
fn williams(a: &SimplifyArgs) -> Result<(), Error> {
    let report = lodeval::app::simplify_williams(&williams_job(a)?)?;
    super::print::warnings(&report.warnings);
    if a.json {
        return emit_json(&report.rows);
    }
    for r in &report.rows {
        emit(&format!(
            "{}  {} triangles ({:.4} of the input)\n",
            r.file.display(),
            r.triangles,
            r.ratio
        ))?;
    }
    Ok(())
}

/// Tell the user (stderr) when a LOD stopped well above its triangle goal: the simplifier ran out
/// of collapses it may make, and the file holds less simplification than asked for.
fn warn_short_of_goals(
    rows: &[lodeval::app::SimplifyRow],
    goals: &[lodeval::simplify::Goal],
    method: &str,
) {
    use lodeval::simplify::Goal;
    for (r, g) in rows.iter().zip(goals) {
        let input = r.triangles as f64 / r.ratio.max(f64::MIN_POSITIVE);
        let target = match *g {
            Goal::Ratio(x) => (x * input).round(),
            Goal::Triangles(n) => n as f64,
            Goal::Error(_) | Goal::Distance(_) | Goal::Vertices(_) => continue,
        };
        if r.triangles as f64 > 1.05 * target + 2.0 {
            note!(
                "warning: {}: {method} stopped at {} triangles, short of the goal of {target}: \
                 every remaining collapse would change the surface's topology or fold it over \
                 (closed parts are not collapsed away, borders only shrink along themselves). Ask \
                 for less reduction, or try another --method.",
                r.file.display(),
                r.triangles
            );
        }
    }
}

/// The `simplify --method williams` request from its arguments.
pub(crate) fn williams_job(a: &SimplifyArgs) -> Result<lodeval::app::WilliamsJob, Error> {
    use lodeval::app::WilliamsViews;
    let rig = a.rig.clone();
    if let Some(c) = a.camera.iter().find(|c| !c.is_finite()) {
        return Err(Error::Usage(format!(
            "--camera {c}: every coordinate must be a finite number"
        )));
    }
    let views = match (a.camera.len(), a.all_views) {
        (0, true) => WilliamsViews::All(rig),
        (0, false) => WilliamsViews::One(rig, a.view.unwrap_or(0)),
        (3, _) => {
            WilliamsViews::Camera(glam::Vec3::new(a.camera[0], a.camera[1], a.camera[2]), None)
        }
        (6, _) => WilliamsViews::Camera(
            glam::Vec3::new(a.camera[0], a.camera[1], a.camera[2]),
            Some(glam::Vec3::new(a.camera[3], a.camera[4], a.camera[5])),
        ),
        (n, _) => {
            return Err(Error::Usage(format!(
                "--camera takes 3 numbers (eye) or 6 (eye, target), not {n}"
            )));
        }
    };
    use lodeval::simplify::williams::StaticGoal;
    let goal = match (a.budget, a.distance) {
        (Some(b), _) => StaticGoal::Budget(b),
        (None, Some(d)) if d.is_finite() && d > 0.0 => StaticGoal::Distance(d),
        (None, Some(d)) => {
            return Err(Error::Usage(format!(
                "--distance {d}: give a positive distance in metres"
            )));
        }
        (None, None) => {
            return Err(Error::Usage(
                "--method williams needs --budget N (triangles) or --distance METRES".into(),
            ));
        }
    };
    let mut job = lodeval::app::WilliamsJob::new(
        a.mesh.clone().expect("clap requires it"),
        a.out.clone().expect("clap requires it"),
        goal,
    );
    job.views = views;
    job.shading = match a.shading {
        Shading::Auto => Shading::Gouraud,
        Shading::Pbr => {
            return Err(Error::Usage(
                "--method williams models Blinn–Phong shading (gouraud, phong, normal-mapped, \
                 unlit); pbr is not one of them"
                    .into(),
            ));
        }
        s => s,
    };
    job.criterion = a.criterion.unwrap_or(Criterion::Perceptual);
    job.size = a.size.unwrap_or(512);
    Ok(job)
}
