//! The plots under the canvas: energy, the followed body and the motors, each quantity on
//! an axis of its own unit with readable numbers, and their export to CSV.

use super::plot_data::{BodyState, PlotData, Sample};
use egui_plot::{GridInput, GridMark, Legend, Line, Plot};
use std::ops::RangeInclusive;

/// Units of the quantities plotted. Lengths are the files' (the thesis's pixels); mass is
/// density × area, so energy and torque are in mass·px²/s².
pub const LENGTH: &str = "px";
pub const ENERGY: &str = "mass·px²/s²";

/// What the body plot shows: one unit at a time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BodyQuantity {
    #[default]
    Position,
    Angle,
    Velocity,
    AngularVelocity,
}

impl BodyQuantity {
    const ALL: [Self; 4] = [
        Self::Position,
        Self::Angle,
        Self::Velocity,
        Self::AngularVelocity,
    ];

    fn label(self) -> &'static str {
        match self {
            Self::Position => "position x, y (px)",
            Self::Angle => "angle (rad)",
            Self::Velocity => "velocity vx, vy (px/s)",
            Self::AngularVelocity => "angular velocity ω (rad/s)",
        }
    }

    /// The lines: name and index into `Sample::body`.
    fn lines(self) -> &'static [(&'static str, usize)] {
        match self {
            Self::Position => &[("x", 0), ("y", 1)],
            Self::Angle => &[("angle", 2)],
            Self::Velocity => &[("vx", 3), ("vy", 4)],
            Self::AngularVelocity => &[("ω", 5)],
        }
    }
}

/// What the motor plot shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MotorQuantity {
    #[default]
    Torque,
    JointGap,
    /// Every joint's angle θ, 0 as placed (where its stops and servos act).
    JointAngle,
    /// Every joint's spin ω_B − ω_A (what its motor drives).
    JointSpin,
}

impl MotorQuantity {
    fn label(self) -> String {
        match self {
            Self::Torque => format!("motor torques ({ENERGY})"),
            Self::JointGap => format!("widest joint gap ({LENGTH})"),
            Self::JointAngle => "joint angles (rad)".to_string(),
            Self::JointSpin => "joint spins, B against A (rad/s)".to_string(),
        }
    }

    const ALL: [Self; 4] = [
        Self::Torque,
        Self::JointGap,
        Self::JointAngle,
        Self::JointSpin,
    ];
}

/// What the plots panel asks the app to do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlotsCommand {
    ExportCsv,
}

#[derive(Debug, Default)]
pub struct PlotsPanel {
    pub body: BodyQuantity,
    pub motors: MotorQuantity,
}

impl PlotsPanel {
    /// `body_name` names the followed body (None: nothing is followed).
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        data: &PlotData,
        body_name: Option<&str>,
    ) -> Option<PlotsCommand> {
        let mut command = None;
        ui.columns(3, |cols| {
            cols[0].horizontal(|ui| {
                ui.label(format!("energy since step 0 ({ENERGY})"));
                if ui
                    .small_button("Export CSV…")
                    .on_hover_text("Write every plotted series, one row per step, to a CSV file")
                    .clicked()
                {
                    command = Some(PlotsCommand::ExportCsv);
                }
            });
            energy_plot(&mut cols[0], data);
            cols[1].horizontal(|ui| {
                match body_name {
                    Some(name) => ui.label(format!("body {name}:")),
                    None => ui.label("click a body on the canvas to plot it:"),
                };
                egui::ComboBox::from_id_salt("body quantity")
                    .selected_text(self.body.label())
                    .show_ui(ui, |ui| {
                        for q in BodyQuantity::ALL {
                            ui.selectable_value(&mut self.body, q, q.label());
                        }
                    })
                    .response
                    .on_hover_text("One quantity at a time, so that one axis has one unit");
            });
            body_plot(&mut cols[1], data, self.body);
            egui::ComboBox::from_id_salt("motor quantity")
                .selected_text(self.motors.label())
                .show_ui(&mut cols[2], |ui| {
                    for q in MotorQuantity::ALL {
                        ui.selectable_value(&mut self.motors, q, q.label());
                    }
                })
                .response
                .on_hover_text(
                    "The motors' torques, the widest joint gap, or every joint's angle or spin",
                );
            motor_plot(&mut cols[2], data, self.motors);
        });
        command
    }
}

type Series = (String, Vec<[f64; 2]>);

fn energy_plot(ui: &mut egui::Ui, data: &PlotData) {
    let (k0, p0) = data
        .samples
        .first()
        .map_or((0.0, 0.0), |s| (s.kinetic, s.potential));
    let lines = vec![
        ("kinetic".to_string(), data.series(|s| Some(s.kinetic))),
        (
            "potential".to_string(),
            data.series(|s| Some(s.potential - p0)),
        ),
        (
            "total".to_string(),
            data.series(|s| Some(s.kinetic + s.potential - k0 - p0)),
        ),
    ];
    plot("energy", ui, data, ENERGY, lines);
}

fn body_plot(ui: &mut egui::Ui, data: &PlotData, quantity: BodyQuantity) {
    let unit = match quantity {
        BodyQuantity::Position => "px",
        BodyQuantity::Angle => "rad",
        BodyQuantity::Velocity => "px/s",
        BodyQuantity::AngularVelocity => "rad/s",
    };
    let lines = quantity
        .lines()
        .iter()
        .map(|&(name, k)| {
            let values = data.series(|s| data.shown_state(s).map(|b| b[k]));
            (name.to_string(), values)
        })
        .collect();
    plot("body", ui, data, unit, lines);
}

fn motor_plot(ui: &mut egui::Ui, data: &PlotData, quantity: MotorQuantity) {
    match quantity {
        MotorQuantity::Torque => {
            let lines = data
                .motor_names
                .iter()
                .enumerate()
                .map(|(k, name)| (name.clone(), data.series(|s| s.torques.get(k).copied())))
                .collect();
            plot("motors", ui, data, ENERGY, lines);
        }
        MotorQuantity::JointGap => {
            let lines = vec![(
                "joint gap".to_string(),
                data.series(|s| Some(s.max_joint_gap)),
            )];
            plot("joint gap", ui, data, LENGTH, lines);
        }
        MotorQuantity::JointAngle | MotorQuantity::JointSpin => {
            let (id, unit) = match quantity {
                MotorQuantity::JointAngle => ("joint angles", "rad"),
                _ => ("joint spins", "rad/s"),
            };
            let pick = |j: (f64, f64)| match quantity {
                MotorQuantity::JointAngle => j.0,
                _ => j.1,
            };
            let lines = data
                .joint_names
                .iter()
                .enumerate()
                .map(|(k, name)| {
                    let values = data.series(|s| s.joints.get(k).map(|&j| pick(j)));
                    (name.clone(), values)
                })
                .collect();
            plot(id, ui, data, unit, lines);
        }
    }
}

/// A time plot of `lines` in `unit`: time in seconds across (at least one second), and a
/// y range never narrower than the numbers' own scale, so that a flat line still shows
/// its value on a labelled axis.
fn plot(id: &str, ui: &mut egui::Ui, data: &PlotData, unit: &str, lines: Vec<Series>) {
    let t0 = data.samples.first().map_or(0.0, |s| s.time);
    let (low, high) = lines
        .iter()
        .flat_map(|(_, points)| points.iter().map(|p| p[1]))
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    let (low, high) = if low <= high { (low, high) } else { (0.0, 0.0) };
    // All zero (nothing moves yet): a unit range, so that the axis still reads sensibly.
    let span = (high - low).max(0.1 * low.abs().max(high.abs()));
    let span = if span > 0.0 { span } else { 1.0 };
    let middle = 0.5 * (low + high);
    let unit_label = unit.to_string();
    Plot::new(id)
        .legend(Legend::default())
        .height(136.0)
        .include_x(t0)
        .include_x(t0 + 1.0)
        .include_y(middle - 0.6 * span)
        .include_y(middle + 0.6 * span)
        .x_axis_label("time (s)")
        .y_axis_label(unit_label)
        .x_axis_formatter(tick_label)
        .y_axis_formatter(tick_label)
        .y_grid_spacer(a_few_labels)
        .y_axis_min_width(44.0)
        .show(ui, |p| {
            for (name, points) in lines {
                p.line(Line::new(name, points));
            }
        });
}

/// Grid lines for a short y axis: labelled ones at a 1-2-5 step that gives two to four
/// labels over the axis, and unlabelled ones a fifth of that apart. (egui_plot's default
/// steps by powers of ten, which in a plot this short often leaves only "0" labelled.)
fn a_few_labels(input: GridInput) -> Vec<GridMark> {
    let (low, high) = input.bounds;
    let span = high - low;
    if !(span.is_finite() && span > 0.0) {
        return Vec::new();
    }
    let step = nice_step(span / 4.0);
    let minor = step / 5.0;
    let first = (low / minor).ceil() as i64;
    let last = (high / minor).floor() as i64;
    (first..=last)
        .map(|k| {
            let value = k as f64 * minor;
            let step_size = if k % 5 == 0 { step } else { minor };
            GridMark { value, step_size }
        })
        .collect()
}

/// The smallest of 1, 2 and 5 × 10ⁿ at least `at_least`.
fn nice_step(at_least: f64) -> f64 {
    let power = 10f64.powf(at_least.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|&s| s >= at_least)
        .unwrap_or(10.0 * power)
}

/// A tick's number with as many digits as the spacing of the ticks needs: `0.25`, `1200`,
/// `2.5e7`, `3e-9`; large and small magnitudes in scientific notation so that the axis
/// stays narrow.
pub fn tick_label(mark: GridMark, _range: &RangeInclusive<f64>) -> String {
    number_at_step(mark.value, mark.step_size)
}

pub fn number_at_step(value: f64, step: f64) -> String {
    if value == 0.0 || !value.is_finite() || !(step.is_finite() && step > 0.0) {
        return if value.is_finite() {
            "0".to_string()
        } else {
            value.to_string()
        };
    }
    let step_exponent = step.log10().floor() as i32;
    let value_exponent = value.abs().log10().floor() as i32;
    if value_exponent >= 5 || step_exponent <= -4 {
        let digits = (value_exponent - step_exponent).clamp(0, 6) as usize;
        let text = format!("{value:.digits$e}");
        // 2.50e7 → 2.5e7: trailing zeros of the mantissa say nothing.
        match text.split_once('e') {
            Some((mantissa, exponent)) if mantissa.contains('.') => {
                let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
                format!("{mantissa}e{exponent}")
            }
            _ => text,
        }
    } else {
        let decimals = (-step_exponent).clamp(0, 6) as usize;
        format!("{value:.decimals$}")
    }
}

/// The plotted series as CSV: a header with units, then one row per recorded step.
pub fn to_csv(data: &PlotData) -> String {
    let mut header = vec![
        "time (s)".to_string(),
        format!("kinetic energy ({ENERGY})"),
        format!("potential energy since step 0 ({ENERGY})"),
        format!("total energy since step 0 ({ENERGY})"),
        format!("widest joint gap ({LENGTH})"),
    ];
    for name in ["x (px)", "y (px)", "angle (rad)", "vx (px/s)", "vy (px/s)"] {
        header.push(format!("body {name}"));
    }
    header.push("body ω (rad/s)".to_string());
    for name in &data.motor_names {
        header.push(format!("torque {name} ({ENERGY})"));
    }
    for name in &data.joint_names {
        header.push(format!("angle {name} (rad)"));
        header.push(format!("spin {name} (rad/s)"));
    }
    let mut out = String::new();
    let quote = |field: &str| {
        if field.contains([',', '"', '\n']) {
            format!("\"{}\"", field.replace('"', "\"\""))
        } else {
            field.to_string()
        }
    };
    out.push_str(
        &header
            .iter()
            .map(|h| quote(h))
            .collect::<Vec<_>>()
            .join(","),
    );
    out.push('\n');
    let start = data
        .samples
        .first()
        .map_or((0.0, 0.0), |s| (s.kinetic, s.potential));
    for s in &data.samples {
        let row = row(
            s,
            start,
            data.shown_state(s),
            data.motor_names.len(),
            data.joint_names.len(),
        );
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

/// One sample as the plots show it: energies as in the energy plot (potential and total
/// since step 0, whose energies are `start`), the shown body's state, the torques.
fn row(
    s: &Sample,
    (k0, p0): (f64, f64),
    body: Option<BodyState>,
    motors: usize,
    joints: usize,
) -> Vec<String> {
    let mut row = vec![
        s.time.to_string(),
        s.kinetic.to_string(),
        (s.potential - p0).to_string(),
        (s.kinetic + s.potential - k0 - p0).to_string(),
        s.max_joint_gap.to_string(),
    ];
    match body {
        Some(b) => row.extend(b.iter().map(|v| v.to_string())),
        None => row.extend(std::iter::repeat_n(String::new(), 6)),
    }
    row.extend((0..motors).map(|k| s.torques.get(k).map_or(String::new(), |t| t.to_string())));
    for k in 0..joints {
        match s.joints.get(k) {
            Some((angle, spin)) => row.extend([angle.to_string(), spin.to_string()]),
            None => row.extend([String::new(), String::new()]),
        }
    }
    row
}

#[cfg(test)]
mod tests {
    use super::number_at_step;

    #[test]
    fn tick_numbers_have_the_digits_their_spacing_needs() {
        assert_eq!(number_at_step(0.25, 0.05), "0.25");
        assert_eq!(number_at_step(1200.0, 100.0), "1200");
        assert_eq!(number_at_step(2.5e7, 5e6), "2.5e7");
        assert_eq!(number_at_step(3e7, 1e7), "3e7");
        assert_eq!(number_at_step(3e-9, 1e-9), "3e-9");
        assert_eq!(number_at_step(0.0, 1e7), "0");
        assert_eq!(number_at_step(-40.0, 20.0), "-40");
    }
}
