//! What the panels ask the app to do. Panels read the document and the runner and return
//! commands; the app applies them in one place (`RoboSimApp::apply`), so that no panel
//! edits the model, runs the physics or touches a file itself.

use super::Selection;
use super::canvas::DebugDraw;
use super::document::ItemKind;
use super::inspector::NewPlacement;
use super::tools::{ShapeOptions, Tool};
use crate::db::Delete;
use crate::model::Model;
use pe::{ContactSolver, Vec2};
use std::path::PathBuf;

/// Where the user goes from this database, once the unsaved-changes question (if any) is
/// answered.
#[derive(Debug, Clone, PartialEq)]
pub enum AfterSave {
    Quit,
    Open(PathBuf),
    OpenExamples,
    NewDatabase,
}

/// Pictures of the canvas the app can write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    Png,
    Svg,
}

/// What the app writes besides the database, each where the user says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Export {
    /// The plotted series as CSV.
    Plots,
    /// The canvas as a picture.
    View(ImageFormat),
    /// The run shown, from step 0 to the step shown (or 10 s), as an animated GIF.
    Gif,
}

impl Export {
    /// The file's extension, without its dot.
    pub fn extension(self) -> &'static str {
        match self {
            Export::Plots => "csv",
            Export::View(ImageFormat::Png) => "png",
            Export::View(ImageFormat::Svg) => "svg",
            Export::Gif => "gif",
        }
    }

    /// What the file holds, as its name and the status bar say it.
    pub fn what(self) -> &'static str {
        match self {
            Export::Plots => "plots",
            Export::View(_) => "view",
            Export::Gif => "run",
        }
    }

    /// The title of the question where to write it.
    pub fn title(self) -> &'static str {
        match self {
            Export::Plots => "Export the plots as CSV",
            Export::View(ImageFormat::Png) => "Export the view as PNG",
            Export::View(ImageFormat::Svg) => "Export the view as SVG",
            Export::Gif => "Export the run as GIF",
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    // Files.
    /// Ask for a folder and open it.
    AskOpen,
    /// Leave this database for another (asking first about unsaved changes).
    Open(AfterSave),
    NewDatabase,
    /// Do what `AfterSave` says without saving.
    Discard(AfterSave),
    /// Save, then do what `AfterSave` says.
    SaveThen(AfterSave),
    Save,
    SaveAs,
    /// Save the database in this folder (chosen in the app's own file chooser).
    SaveIn(PathBuf),
    /// Save although some body cannot be simulated (the user was asked).
    SaveAnyway,
    /// Save over files changed on disk, or dropping unreadable records (the user was asked).
    SaveOverwriting,
    Revert,
    Quit,
    /// Ask where, then write the export.
    Export(Export),
    /// Write the export to this file (chosen in the app's own file chooser).
    ExportTo(Export, PathBuf),
    /// Take up (or forget) the unsaved work an earlier session kept for `folder`.
    Restore(Option<PathBuf>, Model),
    /// An edit of a scene that has run, confirmed: made, and the scene built again at
    /// step 0.
    CommitRestarting(Box<Model>, String),
    DiscardKeptWork(Option<PathBuf>),

    // Edits of the model.
    Select(Selection),
    /// Make `draft` the model; `key` names the field, so that a drag is one undo step.
    Commit {
        draft: Model,
        key: String,
    },
    Rename(Selection, String),
    New(ItemKind),
    Duplicate,
    /// Delete the selected item (the browser's button).
    Delete(Delete),
    /// Delete the selected placement at step 0, or else the selected item.
    DeleteSelected,
    Undo,
    Redo,
    PlaceInScene(NewPlacement),
    /// Move the placement behind simulated body `body` so that its origin goes to `to`
    /// (with the rest of the selection, if the body is selected).
    MovePlacement {
        body: usize,
        to: Vec2,
    },
    /// Turn the placement behind simulated body `body` by `angle` (rad) about its origin
    /// (or, when the body is selected with others, the selection about its middle).
    TurnPlacement {
        body: usize,
        angle: f64,
    },
    /// Move the selected placements by this much (arrow keys at step 0).
    Nudge(Vec2),
    /// Select the placements behind these simulated bodies (a rubber band); with `add`,
    /// besides those already selected.
    Pick {
        bodies: Vec<usize>,
        add: bool,
    },
    /// Add the placement behind this simulated body to the selection, or take it out.
    TogglePick(usize),
    /// The current tool was used at this world point.
    UseTool(Vec2),
    /// A drawing tool was dragged from `from` to `to` (world, snapped): make the body.
    DrawShape {
        from: Vec2,
        to: Vec2,
    },
    /// The body editor changed the selected body's outline.
    SetVertices {
        vertices: Vec<[f64; 2]>,
        key: String,
    },
    CopyPlacement,
    CutPlacement,
    PastePlacement,

    // The simulation.
    SetRunning(bool),
    TogglePlay,
    Step,
    Reset,
    SetSpeed(f64),
    SetSolver(ContactSolver),
    SetSleeping(bool),
    /// Go back to the recorded state nearest this step.
    ScrubTo(u64),

    // The view.
    Fit,
    SetTool(Tool),
    SetSnap(Option<f64>),
    SetShapeOptions(ShapeOptions),
    SetDebug(DebugDraw),
    /// The body the inspector and the plots follow (index into the simulation's bodies).
    Follow(Option<usize>),
    ToggleProblems,
    ShowShortcuts,
    ShowAbout,
    /// The user guide, in a window.
    ShowGuide,

    // Messages for the status bar.
    Inform(String),
    Complain(String),
}
