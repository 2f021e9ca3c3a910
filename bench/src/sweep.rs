//! Work–precision sweeps (`cargo run --release -- sweep`): every engine configuration at
//! h ∈ {1/30, 1/60, 1/120, 1/240} s on the scenes with analytic answers, error against
//! work. Writes docs/bench/sweep.md and one log–log SVG plot per scene.
//!
//! The plots put compute time per simulated second (median time per step ÷ h) on the x
//! axis, not time per step: halving h costs twice the steps for the same motion, and a plot
//! against time per step would show the finer step as free.

use crate::harness::Timing;
use crate::pe_scenes::{self, PeConfig};
use crate::scene::{H, Metric, Pendulum, Pyramid, STACKS, chain};
use crate::{Outcome, box2d_scenes, rapier_scenes};
use pe::{ContactSolver, Integrator};
use plotters::prelude::*;
use std::fmt::Write as _;

const STEPS: [(f64, &str); 4] = [
    (1.0 / 30.0, "1/30"),
    (1.0 / 60.0, "1/60"),
    (1.0 / 120.0, "1/120"),
    (1.0 / 240.0, "1/240"),
];

/// One engine set up one way.
#[derive(Debug, Clone, Copy)]
enum Engine {
    Pe(PeConfig),
    Rapier { iterations: usize },
    Box2d { substeps: i32 },
}

fn configurations() -> Vec<(String, Engine)> {
    let pe = |solver, integrator, soft_substeps| {
        Engine::Pe(PeConfig {
            integrator,
            soft_substeps,
            ..PeConfig::new(solver)
        })
    };
    let mut list = vec![
        (
            "pe exact".to_string(),
            pe(ContactSolver::Exact, Integrator::SemiImplicitEuler, 4),
        ),
        (
            "pe exact, explicit Euler".to_string(),
            pe(ContactSolver::Exact, Integrator::ExplicitEuler, 4),
        ),
        (
            "pe thesis".to_string(),
            pe(ContactSolver::Thesis, Integrator::SemiImplicitEuler, 4),
        ),
    ];
    for substeps in [2, 4, 8] {
        list.push((
            format!("pe soft, {substeps} substeps"),
            pe(ContactSolver::Soft, Integrator::SemiImplicitEuler, substeps),
        ));
    }
    for iterations in [1, 4, 8] {
        list.push((
            format!("rapier2d, {iterations} iterations"),
            Engine::Rapier { iterations },
        ));
    }
    for substeps in [1, 4, 8] {
        list.push((
            format!("Box2D v3, {substeps} substeps"),
            Engine::Box2d { substeps },
        ));
    }
    list
}

/// A scene of the sweep: how to run it in each engine, and its error from the metric.
struct Scene {
    name: &'static str,
    error_name: &'static str,
    run: fn(Engine, f64) -> Outcome,
    error: fn(&Metric) -> f64,
}

/// A stack at step `h`, for as long as `spec.steps` last at `H`.
fn stack(spec: &Pyramid, engine: Engine, h: f64) -> Outcome {
    let spec = Pyramid {
        steps: (spec.steps as f64 * H / h).round() as usize,
        ..*spec
    };
    match engine {
        Engine::Pe(c) => pe_scenes::pyramid(c, &spec, h),
        Engine::Rapier { iterations } => rapier_scenes::pyramid(&spec, h, iterations),
        Engine::Box2d { substeps } => box2d_scenes::pyramid(&spec, h, substeps),
    }
}

/// A stack's error: how far its top box slid sideways plus the most it sank, in boxes.
fn stack_error(m: &Metric) -> f64 {
    match *m {
        Metric::Pyramid {
            top_drift, top_sag, ..
        } => top_drift + top_sag.max(0.0),
        _ => f64::NAN,
    }
}

fn scenes() -> [Scene; 5] {
    [
        Scene {
            name: "pendulum90",
            error_name: "|period error| (relative)",
            run: |engine, h| {
                let spec = Pendulum { name: "", h };
                match engine {
                    Engine::Pe(c) => pe_scenes::pendulum(c, &spec),
                    Engine::Rapier { iterations } => rapier_scenes::pendulum(&spec, iterations),
                    Engine::Box2d { substeps } => box2d_scenes::pendulum(&spec, substeps),
                }
            },
            error: |m| match *m {
                Metric::Pendulum { period_error, .. } => period_error.abs(),
                _ => f64::NAN,
            },
        },
        Scene {
            name: "heavychain",
            error_name: "widest pin gap (link lengths)",
            run: |engine, h| match engine {
                Engine::Pe(c) => pe_scenes::heavy_chain(c, h),
                Engine::Rapier { iterations } => rapier_scenes::heavy_chain(h, iterations),
                Engine::Box2d { substeps } => box2d_scenes::heavy_chain(h, substeps),
            },
            error: |m| match *m {
                Metric::Chain { worst_gap } => worst_gap / chain::LINK.0,
                _ => f64::NAN,
            },
        },
        Scene {
            name: "bounce",
            error_name: "|rebound peak error| (relative)",
            run: |engine, h| match engine {
                Engine::Pe(c) => pe_scenes::bounce(c, h),
                Engine::Rapier { iterations } => rapier_scenes::bounce(h, iterations),
                Engine::Box2d { substeps } => box2d_scenes::bounce(h, substeps),
            },
            error: |m| match *m {
                Metric::Bounce { error, .. } => error.abs(),
                _ => f64::NAN,
            },
        },
        Scene {
            name: STACKS[0].name,
            error_name: "top box's sideways drift + sag over 10 s (boxes)",
            run: |engine, h| stack(&STACKS[0], engine, h),
            error: stack_error,
        },
        Scene {
            name: STACKS[1].name,
            error_name: "top box's sideways drift + sag over 10 s (boxes)",
            run: |engine, h| stack(&STACKS[1], engine, h),
            error: stack_error,
        },
    ]
}

/// One configuration at one step size.
struct Point {
    h: f64,
    h_label: &'static str,
    timing: Timing,
    error: f64,
}

impl Point {
    /// Compute time per simulated second, ms.
    fn work(&self) -> f64 {
        self.timing.median.as_secs_f64() / self.h * 1e3
    }
}

/// Errors below this are drawn at it: a log axis has no zero.
const ERROR_FLOOR: f64 = 1e-9;

pub fn run(out_dir: &str) -> String {
    let configs = configurations();
    let mut md = String::new();
    let _ = writeln!(md, "# Work–precision sweeps\n");
    let _ = writeln!(
        md,
        "Written by `cd bench && cargo run --release -- sweep`. Every configuration at \
         h = 1/30, 1/60, 1/120 and 1/240 s: the error from the analytic answer, and the \
         median time per step (after the warm-up, as in results.md). The plots, \
         `sweep-<scene>.svg`, are log–log: error against compute time per simulated second \
         (time per step ÷ h), since a finer step costs more steps for the same motion; \
         errors below {ERROR_FLOOR:e} are drawn at it. A run that went non-finite shows \
         NaN; one that the wall-time budget cut short is marked † and left off the plot \
         (its error covers only the steps run).\n"
    );
    for scene in scenes() {
        eprint!("{}:", scene.name);
        let mut series: Vec<(String, Vec<Point>)> = Vec::new();
        for (label, engine) in &configs {
            eprint!(" {label}…");
            let points = STEPS
                .iter()
                .map(|&(h, h_label)| {
                    let outcome = (scene.run)(*engine, h);
                    Point {
                        h,
                        h_label,
                        timing: outcome.timing,
                        error: (scene.error)(&outcome.metric),
                    }
                })
                .collect();
            series.push((label.clone(), points));
        }
        eprintln!();
        let _ = writeln!(md, "## {} — {}\n", scene.name, scene.error_name);
        let _ = write!(md, "| configuration |");
        for (_, h) in STEPS {
            let _ = write!(md, " h = {h} |");
        }
        let _ = writeln!(md);
        let _ = writeln!(md, "|---|{}", "---:|".repeat(STEPS.len()));
        for (label, points) in &series {
            let _ = write!(md, "| {label} |");
            for p in points {
                let cut = if p.timing.cut_short() { " †" } else { "" };
                let _ = write!(
                    md,
                    " {:.2e} in {}{cut} |",
                    p.error,
                    crate::format::pretty(p.timing.median)
                );
            }
            let _ = writeln!(md);
        }
        let file = format!("sweep-{}.svg", scene.name);
        match plot(&format!("{out_dir}/{file}"), &scene, &series) {
            Ok(()) => {
                let _ = writeln!(md, "\n![{} work–precision]({file})\n", scene.name);
            }
            Err(e) => {
                let _ = writeln!(md, "\n(plot failed: {e})\n");
            }
        }
    }
    md
}

fn plot(
    path: &str,
    scene: &Scene,
    series: &[(String, Vec<Point>)],
) -> Result<(), Box<dyn std::error::Error>> {
    let finite: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|(_, points)| points)
        .filter(|p| p.error.is_finite() && !p.timing.cut_short())
        .map(|p| (p.work(), p.error.max(ERROR_FLOOR)))
        .collect();
    let (t_min, t_max) = finite
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), &(t, _)| {
            (lo.min(t), hi.max(t))
        });
    let (e_min, e_max) = finite
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), &(_, e)| {
            (lo.min(e), hi.max(e))
        });
    let root = SVGBackend::new(path, (960, 640)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{}: {} against work", scene.name, scene.error_name),
            ("sans-serif", 20),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (t_min / 1.5..t_max * 1.5).log_scale(),
            (e_min / 3.0..e_max * 3.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .bold_line_style(BLACK.mix(0.15))
        .x_desc("compute time per simulated second (ms)")
        .y_desc(scene.error_name)
        .x_label_formatter(&|v| power_label(*v))
        .y_label_formatter(&|v| power_label(*v))
        .draw()?;
    for (k, (label, points)) in series.iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        let xy: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.error.is_finite() && !p.timing.cut_short())
            .map(|p| (p.work(), p.error.max(ERROR_FLOOR)))
            .collect();
        chart
            .draw_series(LineSeries::new(xy.clone(), color.stroke_width(2)))?
            .label(label.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color));
        chart.draw_series(xy.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
        // The coarsest step is labelled so the direction of refinement can be read.
        if let Some(first) = points.iter().find(|p| p.error.is_finite()) {
            let at = (first.work(), first.error.max(ERROR_FLOOR));
            chart.draw_series(std::iter::once(Text::new(
                first.h_label,
                at,
                ("sans-serif", 11).into_font(),
            )))?;
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()?;
    root.present()?;
    Ok(())
}

/// A log axis's tick as a short number: plotters puts ticks at powers of ten computed in
/// floating point (1e-5 comes out as 9.999999999999999e-6), so round to three figures.
fn power_label(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let rounded: f64 = format!("{v:.2e}").parse().unwrap_or(v);
    if (1e-3..1e4).contains(&rounded.abs()) {
        format!("{rounded}")
    } else {
        format!("{rounded:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::power_label;

    #[test]
    fn axis_labels_round_the_floating_point_powers() {
        assert_eq!(power_label(9.999999999999999e-6), "1e-5");
        assert_eq!(power_label(0.09999999999999999), "0.1");
        assert_eq!(power_label(1000.0000000000001), "1000");
        assert_eq!(power_label(1e-9), "1e-9");
        assert_eq!(power_label(25.0), "25");
    }
}
