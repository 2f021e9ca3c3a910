//! The status bar: the problem count (a button for the Problems window), the first
//! problem, the last message, the simulation's step and clock, and the scrub slider that
//! goes back through the last seconds of a run.

use super::Command;
use crate::db::Problem;
use crate::sim::Simulation;

/// The last thing the app said: news, or a failure (shown red).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Message {
    pub text: String,
    pub is_error: bool,
}

/// What the status bar shows.
pub struct Status<'a> {
    pub problems: &'a [Problem],
    pub message: &'a Message,
    pub sim: Option<&'a Simulation>,
    pub solver: pe::ContactSolver,
    /// The steps that can be gone back to (oldest, newest), when there are any.
    pub history: Option<(u64, u64)>,
}

pub fn ui(ui: &mut egui::Ui, s: Status<'_>) -> Vec<Command> {
    let mut out = Vec::new();
    ui.horizontal(|ui| {
        let errors = s.problems.iter().filter(|p| p.is_error()).count();
        let warnings = s.problems.len() - errors;
        let colour = if errors > 0 {
            egui::Color32::LIGHT_RED
        } else if warnings > 0 {
            egui::Color32::YELLOW
        } else {
            egui::Color32::LIGHT_GREEN
        };
        let text = format!("{errors} errors, {warnings} warnings");
        if ui
            .add(egui::Button::new(egui::RichText::new(text).color(colour)))
            .on_hover_text("Show every problem")
            .clicked()
        {
            out.push(Command::ToggleProblems);
        }
        if let Some(first) = s.problems.first() {
            ui.label(first.to_string());
        }
        if !s.message.text.is_empty() {
            if s.message.is_error {
                ui.colored_label(egui::Color32::LIGHT_RED, &s.message.text);
            } else {
                ui.label(&s.message.text);
            }
        }
        ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
            let Some(sim) = s.sim else {
                return;
            };
            let m = sim.metrics();
            ui.label(format!(
                "step {} · t = {:.3} s · h = {:.4} s · {} contacts · {}",
                m.step,
                m.time,
                sim.dt,
                m.contacts,
                s.solver.name()
            ));
            if let Some((oldest, newest)) = s.history
                && newest > oldest
            {
                let mut step = m.step.clamp(oldest, newest);
                let slider = egui::Slider::new(&mut step, oldest..=newest)
                    .show_value(false)
                    .text("back");
                if ui
                    .add(slider)
                    .on_hover_text("Scrub back through the last seconds of the run (pauses it)")
                    .changed()
                {
                    out.push(Command::ScrubTo(step));
                }
            }
        });
    });
    out
}

/// The Problems window: every problem, one per line.
pub fn problems_window(ctx: &egui::Context, problems: &[Problem], open: &mut bool) {
    egui::Window::new("Problems").open(open).show(ctx, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| {
            for p in problems {
                ui.label(p.to_string());
            }
        });
    });
}
