//! Commands that read or write files: open, save (asking first when it matters), revert,
//! unsaved work kept against a crash, and exports of the plots and the view.

use super::command::{AfterSave, Export, ImageFormat};
use super::dialogs::Dialog;
use super::files::{Answer, InAppChooser, PathFor};
use super::{Command, RoboSimApp, Selection, document, plots};
use crate::animation;
use crate::db::{Overwrite, SaveError};
use std::path::{Path, PathBuf};

impl RoboSimApp {
    pub(super) fn apply_file_command(&mut self, command: Command, ctx: &egui::Context, now: f64) {
        match command {
            Command::AskOpen => self.ask_and_open(ctx),
            Command::Open(next) => self.leave_for(next, ctx),
            Command::NewDatabase => self.leave_for(AfterSave::NewDatabase, ctx),
            Command::Discard(next) => self.go(next, ctx),
            Command::SaveThen(next) => {
                self.save(Overwrite::Never, false, None);
                if !self.doc.is_dirty() {
                    self.go(next, ctx);
                }
            }
            Command::Save => self.save(Overwrite::Never, false, None),
            Command::SaveAs => self.save_as(),
            Command::SaveIn(dir) => self.save(Overwrite::Never, false, Some(dir)),
            Command::SaveAnyway => self.save(Overwrite::Never, true, None),
            Command::SaveOverwriting => self.save(Overwrite::Confirmed, true, None),
            Command::Revert => self.revert(),
            Command::Quit => self.leave_for(AfterSave::Quit, ctx),
            Command::Export(export) => {
                if let Some(path) = self.export_path(export) {
                    self.export_to(export, path, ctx);
                }
            }
            Command::ExportTo(export, path) => self.export_to(export, path, ctx),
            Command::Restore(folder, model) => self.restore(folder, model, now),
            Command::DiscardKeptWork(folder) => self.doc.discard_kept_work(folder.as_deref()),
            _ => {}
        }
    }

    /// Reads the files again, dropping unsaved edits (undoable), with the view fitted.
    fn revert(&mut self) {
        if self.doc.revert() {
            self.model_changed();
            self.view.fit();
        }
    }

    /// Takes up the work an earlier session kept, if it was kept for this database.
    fn restore(&mut self, folder: Option<PathBuf>, model: crate::model::Model, now: f64) {
        if folder.as_deref() == self.doc.folder() {
            self.commit(model, "restore", now);
            self.view.fit();
        }
    }

    /// Leaves this database for `next`, asking first if it has unsaved changes.
    fn leave_for(&mut self, next: AfterSave, ctx: &egui::Context) {
        if self.doc.is_dirty() {
            self.dialog = Some(Dialog::Unsaved(next));
        } else {
            self.go(next, ctx);
        }
    }

    fn go(&mut self, next: AfterSave, ctx: &egui::Context) {
        match next {
            AfterSave::Quit => {
                self.close_confirmed = true;
                self.doc
                    .discard_kept_work(self.doc.folder().map(Path::to_path_buf).as_deref());
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
            AfterSave::Open(dir) => self.show_database(Some(&dir)),
            AfterSave::OpenExamples => self.show_database(None),
            AfterSave::NewDatabase => {
                self.doc.start_empty();
                self.toolbar.opened(None);
                self.after_opening();
                self.inform("a new, empty database: Save asks where to keep it".into());
            }
        }
    }

    /// Asks for a database folder and opens it.
    fn ask_and_open(&mut self, ctx: &egui::Context) {
        if let Some(dir) = self.ask_folder("Open a database folder", PathFor::OpenDatabase) {
            self.leave_for(AfterSave::Open(dir), ctx);
        }
    }

    /// Asks for a folder in the system's dialog and returns it; where the system has no
    /// dialog, opens the app's own chooser, which carries on with `purpose` once answered.
    fn ask_folder(&mut self, title: &str, purpose: PathFor) -> Option<PathBuf> {
        let start = self.doc.folder().map(Path::to_path_buf);
        if !self.no_system_dialog {
            match self.files.folder(title, start.as_deref()) {
                Answer::Chosen(dir) => return Some(dir),
                Answer::Cancelled => return None,
                Answer::Unavailable => self.no_system_dialog = true,
            }
        }
        self.in_app_chooser = Some(InAppChooser::folder(title, start.as_deref(), purpose));
        None
    }

    /// Makes the database in `folder` (or the examples) the one edited.
    fn show_database(&mut self, folder: Option<&Path>) {
        self.doc.reopen(folder);
        self.toolbar.opened(folder);
        self.after_opening();
    }

    fn after_opening(&mut self) {
        self.select_first_scene();
        self.copied = None;
        self.view.fit();
        self.offer_restore();
    }

    /// Saves to the database's folder, to `folder`, or to the folder typed in the path
    /// field or chosen in a dialog when it has none. Unless `shapes_confirmed`, asks first
    /// when a body's outline is not a convex polygon (the simulation cannot use it).
    fn save(&mut self, overwrite: Overwrite, shapes_confirmed: bool, folder: Option<PathBuf>) {
        if !shapes_confirmed
            && let Some(question) = document::unusable_bodies_question(self.doc.model())
        {
            self.dialog = Some(Dialog::SaveUnusable(question));
            return;
        }
        let folder = match folder {
            Some(f) => Some(f),
            None if self.doc.folder().is_some() => None,
            None => {
                let typed = self.toolbar.path_input.trim();
                if typed.is_empty() {
                    match self.ask_folder("Save the database in…", PathFor::SaveDatabase) {
                        Some(dir) => Some(dir),
                        None => return,
                    }
                } else {
                    Some(PathBuf::from(typed))
                }
            }
        };
        match self.doc.save(folder.as_deref(), overwrite) {
            Ok(()) => {
                let saved_in = self.doc.folder().map(Path::to_path_buf);
                self.toolbar.opened(saved_in.as_deref());
                self.inform(format!(
                    "saved to {}",
                    saved_in.map_or(String::new(), |d| d.display().to_string())
                ));
            }
            Err(e @ (SaveError::ChangedOnDisk(_) | SaveError::WouldDropRecords(_))) => {
                self.dialog = Some(Dialog::Overwrite(e.to_string()));
            }
            Err(e) => self.complain(e.to_string()),
        }
    }

    fn save_as(&mut self) {
        if let Some(dir) = self.ask_folder("Save the database in…", PathFor::SaveDatabase) {
            self.save(Overwrite::Never, false, Some(dir));
        }
    }

    /// Keeps a copy of unsaved work, to be offered back after a crash: soon after an edit,
    /// and when eframe asks (every 30 s and on exit).
    pub(super) fn keep_unsaved_work(&mut self) {
        if self.close_confirmed {
            let folder = self.doc.folder().map(Path::to_path_buf);
            self.doc.discard_kept_work(folder.as_deref());
            return;
        }
        if let Err(e) = self.doc.keep_unsaved_work() {
            self.complain(format!("could not keep a copy of unsaved work: {e}"));
        }
    }

    /// Writes the copy of unsaved work when it is due; wakes the app for it.
    pub(super) fn autosave_tick(&mut self, ctx: &egui::Context, now: f64) {
        match self.doc.autosave_tick(now) {
            Ok(Some(left)) => {
                ctx.request_repaint_after(std::time::Duration::from_secs_f64(left + 0.05));
            }
            Ok(None) => {}
            Err(e) => self.complain(format!("could not keep a copy of unsaved work: {e}")),
        }
    }

    /// Offers back work an earlier session kept for this database and never saved.
    pub(super) fn offer_restore(&mut self) {
        if let Some(kept) = self.doc.kept_work() {
            let folder = self.doc.folder().map(Path::to_path_buf);
            self.dialog = Some(Dialog::Restore(folder, kept));
        }
    }

    /// A file name for an export of what the canvas shows.
    fn export_name(&self, export: Export) -> String {
        let shown = match &self.selection {
            Some(Selection::Scene(n) | Selection::Robot(n) | Selection::Body(n)) => n.clone(),
            None => "robosim".to_string(),
        };
        format!("{shown} {}.{}", export.what(), export.extension())
    }

    /// Asks where to write an export, starting where the last one went (else in the
    /// database's folder); None when the user cancelled, or when the app's own chooser
    /// asks (it carries on once answered).
    fn export_path(&mut self, export: Export) -> Option<PathBuf> {
        if export != Export::Plots && self.runner.sim().is_none() {
            self.complain(format!(
                "nothing to export: no scene is shown ({})",
                export.what()
            ));
            return None;
        }
        let folder =
            (self.export_folder.clone()).or_else(|| self.doc.folder().map(Path::to_path_buf));
        let (title, name, extension) =
            (export.title(), self.export_name(export), export.extension());
        if !self.no_system_dialog {
            match self
                .files
                .new_file(title, &name, extension, folder.as_deref())
            {
                Answer::Chosen(path) => return Some(path),
                Answer::Cancelled => return None,
                Answer::Unavailable => self.no_system_dialog = true,
            }
        }
        self.in_app_chooser = Some(InAppChooser::export_file(
            title,
            &name,
            folder.as_deref(),
            export,
        ));
        None
    }

    fn export_to(&mut self, export: Export, path: PathBuf, ctx: &egui::Context) {
        self.export_folder = path.parent().map(Path::to_path_buf);
        match export {
            Export::Plots => {
                let csv = plots::to_csv(&self.runner.plot_data);
                self.write_export(&path, csv.as_bytes(), "plots");
            }
            Export::View(format) => self.export_view(format, path, ctx),
            Export::Gif => self.export_gif(path, ctx),
        }
    }

    fn write_export(&mut self, path: &Path, bytes: &[u8], what: &str) {
        match std::fs::write(path, bytes) {
            Ok(()) => self.inform(format!("{what} written to {}", path.display())),
            Err(e) => self.complain(format!("cannot write {}: {e}", path.display())),
        }
    }

    /// Writes the canvas as SVG now, or asks egui for a screenshot to write as PNG.
    fn export_view(&mut self, format: ImageFormat, path: PathBuf, ctx: &egui::Context) {
        match format {
            ImageFormat::Svg => {
                let Some(sim) = self.runner.sim() else {
                    return self.complain("nothing to export: no scene is shown".into());
                };
                let marks = super::canvas::draw::Highlights {
                    selected: &[],
                    overlaps: &[],
                };
                let shapes = super::canvas::draw::scene(
                    sim,
                    &self.view.camera,
                    self.view.rect,
                    &self.view.debug,
                    marks,
                );
                let svg = super::canvas::draw::svg(&shapes, self.view.rect);
                self.write_export(&path, svg.as_bytes(), "view");
            }
            ImageFormat::Png => {
                // Taken of the next frame, drawn without the editing hints.
                self.view.png_pending = Some(path);
                ctx.request_repaint();
            }
        }
    }

    /// At the end of the frame drawn for a PNG export: asks the integration for its
    /// pixels, which it hands back after the frame.
    pub(super) fn take_png(&mut self, ctx: &egui::Context) {
        let Some(path) = self.view.png_pending.take() else {
            return;
        };
        let (rect, scale) = (self.view.rect, ctx.pixels_per_point());
        let written = self.export_news.clone();
        let repaint = ctx.clone();
        ctx.request_screenshot(move |image| {
            let outcome = write_png(&image.region(&rect, Some(scale)), &path)
                .map(|p| format!("view written to {}", p.display()));
            if let Ok(mut slot) = written.lock() {
                *slot = Some(outcome);
            }
            repaint.request_repaint();
        });
    }

    /// Reports an export another thread finished since the last frame.
    pub(super) fn export_news(&mut self) {
        let outcome = self
            .export_news
            .lock()
            .ok()
            .and_then(|mut slot| slot.take());
        match outcome {
            Some(Ok(news)) => self.inform(news),
            Some(Err(why)) => self.complain(why),
            None => {}
        }
    }

    /// Records the run shown as an animated GIF on a thread of its own (a long run takes
    /// seconds to simulate and encode): from step 0 to the step shown, or the first 10 s
    /// when it is at step 0. Mouse pulls and the world's edge are the window's alone: the
    /// recording is the scene's own physics.
    fn export_gif(&mut self, path: PathBuf, ctx: &egui::Context) {
        let Some(mut sim) = self.runner.sim().cloned() else {
            return self.complain("nothing to record: no scene is shown".into());
        };
        let steps = match sim.step_count() {
            0 => (10.0 / sim.dt).round() as u64,
            shown => shown,
        };
        sim.reset();
        self.inform(format!("recording {steps} steps as a GIF…"));
        let news = self.export_news.clone();
        let repaint = ctx.clone();
        std::thread::spawn(move || {
            let every = animation::steps_per_frame(sim.dt);
            let outcome = animation::record(&mut sim, steps, every).and_then(|recording| {
                let gif = recording.to_gif(animation::WIDTH, animation::HEIGHT)?;
                animation::write_atomically(&path, &gif)?;
                Ok(format!(
                    "run written to {} ({} frames)",
                    path.display(),
                    recording.frame_count()
                ))
            });
            if let Ok(mut slot) = news.lock() {
                *slot = Some(outcome);
            }
            repaint.request_repaint();
        });
    }
}

/// Writes `image` to `path` as PNG.
fn write_png(image: &egui::ColorImage, path: &Path) -> Result<PathBuf, String> {
    use eframe::icon_data::IconDataExt;
    let rgba = egui::IconData {
        width: image.size[0] as u32,
        height: image.size[1] as u32,
        rgba: image.as_raw().to_vec(),
    };
    let png = rgba
        .to_png_bytes()
        .map_err(|e| format!("cannot encode the view as PNG: {e}"))?;
    std::fs::write(path, png).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(path.to_path_buf())
}
