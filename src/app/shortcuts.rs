//! Every keyboard shortcut in one table: the app reads keys through it, the menus show
//! it beside their entries and the shortcut sheet lists it.

use egui::{Key, KeyboardShortcut, Modifiers};

/// What a shortcut asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    Save,
    SaveAs,
    Open,
    Undo,
    Redo,
    Cut,
    Copy,
    Paste,
    Duplicate,
    Delete,
    PlayPause,
    Step,
    Reset,
    Fit,
    RotateLeft,
    RotateRight,
    /// While running, joint motors faster; at step 0, the selection up a grid step.
    Up,
    /// While running, joint motors slower; at step 0, the selection down a grid step.
    Down,
    /// At step 0, the selection a grid step left.
    Left,
    /// At step 0, the selection a grid step right.
    Right,
    ShowShortcuts,
    SelectTool,
    BoxTool,
    PolygonTool,
}

const fn command(key: Key) -> KeyboardShortcut {
    KeyboardShortcut::new(Modifiers::COMMAND, key)
}

const fn plain(key: Key) -> KeyboardShortcut {
    KeyboardShortcut::new(Modifiers::NONE, key)
}

/// The table. Shortcuts with Ctrl (⌘) come first: a key press matches the first entry it
/// fits, so Ctrl+S saves and never also steps.
pub const SHORTCUTS: &[(Action, KeyboardShortcut, &str)] = &[
    (
        Action::SaveAs,
        KeyboardShortcut::new(Modifiers::COMMAND.plus(Modifiers::SHIFT), Key::S),
        "Save the database in another folder",
    ),
    (Action::Save, command(Key::S), "Save the database"),
    (Action::Open, command(Key::O), "Open a database folder"),
    (
        Action::Redo,
        KeyboardShortcut::new(Modifiers::COMMAND.plus(Modifiers::SHIFT), Key::Z),
        "Redo",
    ),
    (Action::Undo, command(Key::Z), "Undo the last edit"),
    (Action::Redo, command(Key::Y), "Redo"),
    (Action::Cut, command(Key::X), "Cut the selected placements"),
    (
        Action::Copy,
        command(Key::C),
        "Copy the selected placements",
    ),
    (
        Action::Paste,
        command(Key::V),
        "Paste the copied placements in free space at the view's centre",
    ),
    (
        Action::Duplicate,
        command(Key::D),
        "Duplicate the selected placements (at step 0), or else the selected item",
    ),
    (
        Action::Delete,
        plain(Key::Delete),
        "Delete the selected placements, or else the selected item",
    ),
    (Action::PlayPause, plain(Key::Space), "Run or pause"),
    (Action::Step, plain(Key::S), "One physics step"),
    (Action::Reset, plain(Key::R), "Back to step 0"),
    (
        Action::Fit,
        plain(Key::F),
        "Fit the view to the scene (or the body)",
    ),
    (
        Action::RotateLeft,
        plain(Key::Q),
        "Turn the selected placements 15° anticlockwise (step 0)",
    ),
    (
        Action::RotateRight,
        plain(Key::E),
        "Turn the selected placements 15° clockwise (step 0)",
    ),
    (
        Action::Up,
        plain(Key::ArrowUp),
        "At step 0: move the selection up one grid step. While running: joint motors faster (steps of ½ their speed, up to 2×)",
    ),
    (
        Action::Down,
        plain(Key::ArrowDown),
        "At step 0: move the selection down one grid step. While running: joint motors slower, then backwards (down to −2×)",
    ),
    (
        Action::Left,
        plain(Key::ArrowLeft),
        "At step 0: move the selection left one grid step",
    ),
    (
        Action::Right,
        plain(Key::ArrowRight),
        "At step 0: move the selection right one grid step",
    ),
    (
        Action::BoxTool,
        plain(Key::B),
        "Box tool: drag on the canvas to draw a new body (scene or robot)",
    ),
    (
        Action::PolygonTool,
        plain(Key::P),
        "Polygon tool: drag from the centre out to draw a regular polygon",
    ),
    (
        Action::SelectTool,
        plain(Key::Escape),
        "Back to the select tool",
    ),
    (Action::ShowShortcuts, plain(Key::F1), "This list"),
];

/// The shortcut that triggers `action` (the first listed), for menus to show.
pub fn of(action: Action) -> Option<KeyboardShortcut> {
    SHORTCUTS
        .iter()
        .find(|(a, _, _)| *a == action)
        .map(|(_, s, _)| *s)
}

/// The actions pressed this frame, consumed so that no widget also sees them. While a text
/// field has the focus, keys without Ctrl type into it and Ctrl+Z/Y undo the typing.
/// Escape is taken only while a tool other than select is on (`tool_on`): otherwise it
/// stays egui's, which closes menus and popups with it. Keys in `motor_keys` (bound to
/// the running scene's motors) are no plain shortcut's.
pub fn pressed(
    input: &mut egui::InputState,
    typing: bool,
    tool_on: bool,
    motor_keys: &[Key],
) -> Vec<Action> {
    let mut actions = Vec::new();
    for (action, shortcut, _) in SHORTCUTS {
        if *action == Action::SelectTool && !tool_on {
            continue;
        }
        if !shortcut.modifiers.command && motor_keys.contains(&shortcut.logical_key) {
            continue;
        }
        let needs_command = shortcut.modifiers.command;
        if typing && (!needs_command || matches!(action, Action::Undo | Action::Redo)) {
            continue;
        }
        if typing && matches!(action, Action::Cut | Action::Copy | Action::Paste) {
            continue;
        }
        if input.consume_shortcut(shortcut) {
            actions.push(*action);
        }
    }
    // Integrations turn Ctrl+C, X, V into clipboard events rather than key presses.
    if !typing {
        for event in &input.events {
            let action = match event {
                egui::Event::Copy => Action::Copy,
                egui::Event::Cut => Action::Cut,
                egui::Event::Paste(_) => Action::Paste,
                _ => continue,
            };
            if !actions.contains(&action) {
                actions.push(action);
            }
        }
    }
    actions
}
