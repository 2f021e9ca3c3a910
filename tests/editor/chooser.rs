//! Where the system has no file dialog (no desktop portal, no zenity), Open, Save As and
//! the exports ask in the app's own chooser and carry on once it is answered.

use super::{click, harness_with_files, scratch_db};
use egui::accesskit::Role;
use egui::{Key, Modifiers};
use egui_kittest::Harness;
use egui_kittest::kittest::{AccessKitNode, Queryable};
use robosim::app::RoboSimApp;
use robosim::app::files::{Answer, Scripted};
use robosim::db::Database;

/// Replaces the text of the chooser's field showing `shown` (it has no label of its own).
pub(super) fn retype(h: &mut Harness<'_, RoboSimApp>, shown: &str, text: &str) {
    let field = |n: &AccessKitNode<'_>| {
        n.role() == Role::TextInput
            && n.value().as_deref() == Some(shown)
            && n.labelled_by().next().is_none()
    };
    h.get_by(field).focus();
    h.run_steps(1);
    h.key_press_modifiers(Modifiers::COMMAND, Key::A);
    h.run_steps(1);
    h.get_by(field).type_text(text);
    h.run_steps(2);
}

#[test]
fn save_as_without_a_file_dialog_saves_into_a_new_folder_made_in_the_apps_chooser() {
    let dir = scratch_db();
    let mut h = harness_with_files(dir.path(), Scripted::new([Answer::Unavailable]));
    click(&mut h, "File");
    h.get_by_label_contains("Save As").click();
    h.run_steps(4);
    // The chooser starts in the database's folder and offers to make one inside it.
    retype(&mut h, "new database", "copy of the demos");
    click(&mut h, "New Folder");
    let made = dir.path().join("copy of the demos");
    assert!(made.is_dir(), "the chooser made the folder");
    click(&mut h, "Choose this folder");
    h.run_steps(2);
    assert_eq!(h.state().db().dir.as_deref(), Some(made.as_path()));
    for name in ["bodies.xml", "robots.xml", "scenes.xml"] {
        assert_eq!(
            std::fs::read(made.join(name)).unwrap(),
            std::fs::read(dir.path().join(name)).unwrap(),
            "{name}: an unedited database is saved byte for byte"
        );
    }
    let (saved, problems) = Database::load(&made);
    assert!(problems.is_empty(), "{problems:?}");
    assert_eq!(saved.model.scenes.len(), 10);
    assert!(
        h.state().status().contains("saved to"),
        "{}",
        h.state().status()
    );
}

#[test]
fn open_without_a_file_dialog_asks_in_the_apps_chooser_and_cancel_changes_nothing() {
    let dir = scratch_db();
    let other = scratch_db();
    let mut h = harness_with_files(dir.path(), Scripted::new([Answer::Unavailable]));
    click(&mut h, "Open…");
    h.run_steps(2);
    click(&mut h, "Cancel");
    assert_eq!(h.state().db().dir.as_deref(), Some(dir.path()));
    assert!(h.query_by_label("Choose this folder").is_none(), "closed");

    // Asked again, the app goes straight to its own chooser: the system has none.
    click(&mut h, "Open…");
    h.run_steps(2);
    let shown = dir.path().display().to_string();
    retype(&mut h, &shown, &other.path().display().to_string());
    h.key_press(Key::Enter);
    h.run_steps(2);
    click(&mut h, "Choose this folder");
    h.run_steps(2);
    assert_eq!(h.state().db().dir.as_deref(), Some(other.path()));
}

#[test]
fn an_export_without_a_file_dialog_is_written_where_the_apps_chooser_says() {
    let dir = scratch_db();
    let mut h = harness_with_files(dir.path(), Scripted::new([Answer::Unavailable]));
    click(&mut h, "File");
    click(&mut h, "Export view as SVG…");
    h.run_steps(2);
    let offered = "car on terrain view.svg";
    retype(&mut h, offered, "boxes.svg");
    click(&mut h, "Export");
    let svg = std::fs::read_to_string(dir.path().join("boxes.svg")).expect("written");
    assert!(
        svg.starts_with("<svg") && svg.contains("<polygon"),
        "{svg:.200}"
    );
}

/// The next export is offered where the last one went, not back in the database's folder
/// (a second person's hour: every export landed beside the XML files by default).
#[test]
fn the_next_export_is_offered_where_the_last_one_went() {
    let dir = scratch_db();
    let exports = dir.path().join("exports");
    std::fs::create_dir(&exports).unwrap();
    let first = exports.join("first.svg");
    let mut h = harness_with_files(
        dir.path(),
        Scripted::new([Answer::Chosen(first.clone()), Answer::Unavailable]),
    );
    for _ in 0..2 {
        click(&mut h, "File");
        click(&mut h, "Export view as SVG…");
        h.run_steps(2);
    }
    assert!(first.exists(), "the first export was written");
    let shown = exports.display().to_string();
    let field = |n: &AccessKitNode<'_>| {
        n.role() == Role::TextInput
            && n.value().as_deref() == Some(shown.as_str())
            && n.labelled_by().next().is_none()
    };
    assert!(h.query_by(field).is_some(), "the chooser opened in {shown}");
}
