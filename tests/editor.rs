//! The editor driven headless through egui_kittest (issue 7): clicks on the canvas, typed
//! fields, shortcuts; every test checks the model, the files or the simulation it changed.

use egui::{Event, Key, Modifiers, PointerButton, Pos2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use robosim::app::{RoboSimApp, Selection};
use robosim::db::Database;
use std::path::Path;

/// A copy of the default database in a temporary folder, so that tests may save.
fn scratch_db() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for name in ["bodies.xml", "robots.xml", "scenes.xml"] {
        let from = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("data")
            .join(name);
        std::fs::copy(from, dir.path().join(name)).unwrap();
    }
    dir
}

fn harness(dir: &Path) -> Harness<'static, RoboSimApp> {
    let app = RoboSimApp::new(Some(dir.to_path_buf()));
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(move |_| app);
    h.run_steps(3);
    h
}

/// The app on `dir`'s database, asking for paths through `files`.
fn harness_with_files(
    dir: &Path,
    files: robosim::app::files::Scripted,
) -> Harness<'static, RoboSimApp> {
    let app = RoboSimApp::new(Some(dir.to_path_buf())).with_file_chooser(Box::new(files));
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(move |_| app);
    h.run_steps(3);
    h
}

/// Clicks the canvas at world point (x, y).
fn click_world(h: &mut Harness<'_, RoboSimApp>, x: f64, y: f64, modifiers: Modifiers) {
    let app = h.state();
    let pos: Pos2 = app
        .camera()
        .to_screen(app.canvas_rect(), pe::Vec2::new(x, y));
    assert!(
        app.canvas_rect().contains(pos),
        "({x}, {y}) is off the canvas"
    );
    h.event(Event::ModifiersChanged(modifiers));
    h.event(Event::PointerMoved(pos));
    h.run_steps(1);
    for pressed in [true, false] {
        h.event(Event::PointerButton {
            pos,
            button: PointerButton::Primary,
            pressed,
            modifiers,
        });
        h.run_steps(1);
    }
    h.event(Event::ModifiersChanged(Modifiers::NONE));
    h.run_steps(1);
}

/// Drags on the canvas with the primary button from world point `from` to `to`.
fn drag_world(h: &mut Harness<'_, RoboSimApp>, from: (f64, f64), to: (f64, f64)) {
    drag_world_holding(h, from, to, Modifiers::NONE);
}

/// `drag_world` with `modifiers` held (Shift adds a rubber band's bodies to the
/// selection).
fn drag_world_holding(
    h: &mut Harness<'_, RoboSimApp>,
    from: (f64, f64),
    to: (f64, f64),
    modifiers: Modifiers,
) {
    let app = h.state();
    let screen = |(x, y): (f64, f64)| {
        app.camera()
            .to_screen(app.canvas_rect(), pe::Vec2::new(x, y))
    };
    let (start, end) = (screen(from), screen(to));
    drag_screen_holding(h, start, end, 4, modifiers);
}

/// Drags with the primary button from screen point `start` to `end` in `moves` frames,
/// no modifier held.
fn drag_screen(h: &mut Harness<'_, RoboSimApp>, start: Pos2, end: Pos2, moves: usize) {
    drag_screen_holding(h, start, end, moves, Modifiers::NONE);
}

/// `drag_screen` with `modifiers` held from the press to the release.
fn drag_screen_holding(
    h: &mut Harness<'_, RoboSimApp>,
    start: Pos2,
    end: Pos2,
    moves: usize,
    modifiers: Modifiers,
) {
    press_and_move(h, start, end, moves, modifiers);
    release(h, end, modifiers);
}

/// Presses the primary button at screen point `start` and moves to `end` in `moves`
/// frames, `modifiers` held, the button still down.
fn press_and_move(
    h: &mut Harness<'_, RoboSimApp>,
    start: Pos2,
    end: Pos2,
    moves: usize,
    modifiers: Modifiers,
) {
    h.event(Event::ModifiersChanged(modifiers));
    h.event(Event::PointerMoved(start));
    h.run_steps(1);
    h.event(primary_button(start, true, modifiers));
    h.run_steps(1);
    for k in 1..=moves {
        h.event(Event::PointerMoved(
            start + (end - start) * (k as f32 / moves as f32),
        ));
        h.run_steps(1);
    }
}

/// Releases the primary button at screen point `at`.
fn release(h: &mut Harness<'_, RoboSimApp>, at: Pos2, modifiers: Modifiers) {
    h.event(primary_button(at, false, modifiers));
    h.run_steps(2);
}

fn primary_button(pos: Pos2, pressed: bool, modifiers: Modifiers) -> Event {
    Event::PointerButton {
        pos,
        button: PointerButton::Primary,
        pressed,
        modifiers,
    }
}

fn click(h: &mut Harness<'_, RoboSimApp>, label: &str) {
    h.get_by_label(label).click();
    h.run_steps(2);
}

/// Replaces the text of the field labelled `label` and commits it with Enter.
fn type_into(h: &mut Harness<'_, RoboSimApp>, label: &str, text: &str) {
    h.get_by_label(label).focus();
    h.run_steps(1);
    h.key_press_modifiers(Modifiers::COMMAND, Key::A);
    h.run_steps(1);
    h.get_by_label(label).type_text(text);
    h.run_steps(1);
    h.key_press(Key::Enter);
    h.run_steps(2);
}

fn new_item(h: &mut Harness<'_, RoboSimApp>, kind: &str) {
    click(h, "New");
    click(h, kind);
}

/// Drags the rotate handle at screen point `handle`, straight above `origin`, `sweep`
/// degrees about `origin` (clockwise on screen: y down, the turn's positive sense) in
/// `moves` moves, each followed by a frame with the pointer at rest, as a real mouse
/// gives.
fn sweep_handle(
    h: &mut Harness<'_, RoboSimApp>,
    origin: Pos2,
    handle: Pos2,
    sweep: f32,
    moves: usize,
) {
    let radius = origin.y - handle.y;
    let at = |degrees: f32| {
        let a = degrees.to_radians();
        origin + egui::vec2(radius * a.sin(), -radius * a.cos())
    };
    h.event(Event::PointerMoved(handle));
    h.run_steps(1);
    h.event(primary_button(at(0.0), true, Modifiers::NONE));
    h.run_steps(1);
    for k in 1..=moves {
        h.event(Event::PointerMoved(at(sweep * k as f32 / moves as f32)));
        h.run_steps(2);
    }
    release(h, at(sweep), Modifiers::NONE);
}

/// A new body made with New → body; its name.
fn new_body_selected(h: &mut Harness<'_, RoboSimApp>) -> String {
    new_item(h, "body");
    match h.state().selection() {
        Some(Selection::Body(name)) => name.clone(),
        other => panic!("a new body is selected, not {other:?}"),
    }
}

/// Ctrl+C pressed (the key going down alone, so that the frame it is read in is the last
/// one run); the text the app put on the system clipboard.
fn copy_to_clipboard(h: &mut Harness<'_, RoboSimApp>) -> String {
    h.event(Event::Key {
        key: Key::C,
        physical_key: None,
        pressed: true,
        repeat: false,
        modifiers: Modifiers::COMMAND,
    });
    h.run_steps(1);
    h.output()
        .platform_output
        .commands
        .iter()
        .find_map(|c| match c {
            egui::OutputCommand::CopyText(text) => Some(text.clone()),
            _ => None,
        })
        .expect("text on the clipboard")
}

#[test]
fn a_body_drawn_by_clicks_is_saved_and_found_again() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    let name = new_body_selected(&mut h);
    click(&mut h, "Clear and draw");
    assert!(h.state().model().body(&name).unwrap().vertices.is_empty());
    for (x, y) in [(-15.0, -10.0), (15.0, -10.0), (15.0, 10.0), (-15.0, 10.0)] {
        click_world(&mut h, x, y, Modifiers::NONE);
    }
    let body = h.state().model().body(&name).unwrap().clone();
    assert_eq!(
        body.vertices,
        vec![[-15.0, -10.0], [15.0, -10.0], [15.0, 10.0], [-15.0, 10.0]]
    );
    type_into(&mut h, "density", "2.5");
    assert_eq!(h.state().model().body(&name).unwrap().density, 2.5);

    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run_steps(2);
    assert!(!h.state().db().is_dirty(), "saved: {}", h.state().status());
    let (reloaded, problems) = Database::load(dir.path());
    assert!(problems.iter().all(|p| !p.is_error()), "{problems:#?}");
    let saved = reloaded
        .model
        .body(&name)
        .expect("the new body is in bodies.xml");
    assert_eq!(saved.vertices, body.vertices);
    assert_eq!(saved.density, 2.5);
    let area = 30.0 * 20.0;
    let mass = robosim::db::polygon(saved).unwrap().mass_properties().area * saved.density;
    assert!((mass - 2.5 * area).abs() < 1e-9, "mass {mass}");
}

#[test]
fn a_click_that_would_dent_the_body_is_refused_with_a_message() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    new_item(&mut h, "body");
    let Some(Selection::Body(name)) = h.state().selection().cloned() else {
        panic!()
    };
    click(&mut h, "Clear and draw");
    for (x, y) in [(-20.0, -20.0), (20.0, -20.0), (0.0, 20.0)] {
        click_world(&mut h, x, y, Modifiers::NONE);
    }
    let triangle = h.state().model().body(&name).unwrap().vertices.clone();
    assert_eq!(triangle.len(), 3);
    // Inside the triangle: no edge can take it and stay convex.
    click_world(&mut h, 0.0, -5.0, Modifiers::NONE);
    assert_eq!(h.state().model().body(&name).unwrap().vertices, triangle);
    assert!(
        h.state().status().contains("non-convex"),
        "status: {}",
        h.state().status()
    );
    h.get_by_label_contains("non-convex");
    // Shift+click takes it anyway; the outline is then flagged invalid until repaired.
    click_world(&mut h, 0.0, -5.0, Modifiers::SHIFT);
    assert_eq!(h.state().model().body(&name).unwrap().vertices.len(), 4);
    assert!(
        h.state()
            .problems()
            .iter()
            .any(|p| p.is_error() && p.to_string().contains(&name))
    );
    click(&mut h, "Convex hull");
    assert_eq!(h.state().model().body(&name).unwrap().vertices.len(), 3);
    assert!(!h.state().problems().iter().any(|p| p.is_error()));
}

#[test]
fn a_two_body_robot_with_a_joint_and_a_motor_simulates() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    new_item(&mut h, "robot");
    let Some(Selection::Robot(name)) = h.state().selection().cloned() else {
        panic!()
    };
    for _ in 0..2 {
        click(&mut h, "+ body");
        click(&mut h, "obdelnik");
    }
    let robot = h.state().model().robot(&name).unwrap().clone();
    assert_eq!(robot.bodies.len(), 2);
    // obdelnik is 40 wide: the second body sits 30 to the right, overlapping by 10.
    assert_eq!(
        (robot.bodies[1].placement.x, robot.bodies[1].placement.y),
        (30.0, 0.0)
    );
    assert!(
        h.state()
            .problems()
            .iter()
            .any(|p| p.to_string().contains("connected")),
        "two loose bodies are flagged live"
    );

    click(&mut h, "Add joint");
    click_world(&mut h, 5.0, 30.0, Modifiers::NONE); // outside both
    assert!(
        h.state().status().contains("covered by 0"),
        "{}",
        h.state().status()
    );
    click_world(&mut h, 15.0, 0.0, Modifiers::NONE);
    let robot = h.state().model().robot(&name).unwrap().clone();
    assert_eq!(robot.joints.len(), 1, "{}", h.state().status());
    let j = &robot.joints[0];
    assert_eq!(
        (j.body_a.as_str(), j.body_b.as_str()),
        ("obdelnik", "obdelnik 2")
    );
    assert_eq!((j.anchor_ax, j.anchor_ay), (15.0, 0.0));
    assert!(
        !h.state()
            .problems()
            .iter()
            .any(|p| p.to_string().contains("connected"))
    );

    click(&mut h, "Add joint"); // back to selecting
    h.get_by_label_contains("obdelnik – obdelnik 2").click();
    h.run_steps(2);
    click(&mut h, "joint motor");
    let motor = h.state().model().robot(&name).unwrap().joints[0]
        .motor
        .clone();
    let motor = motor.expect("the joint has a motor");
    assert!(motor.max_torque > 0.0 && motor.angular != 0.0);

    // Run the robot preview: the motor turns body A against body B about the pin.
    click(&mut h, "Play");
    h.run_steps(30);
    let sim = h.state().sim().unwrap();
    assert!(sim.step_count() >= 20, "steps: {}", sim.step_count());
    let m = sim.metrics();
    assert!(
        m.max_joint_gap < 1e-3,
        "the pin holds: gap {}",
        m.max_joint_gap
    );
    let [a, b] = [0, 1].map(|i| {
        sim.world
            .body(sim.bodies[i].handle)
            .unwrap()
            .angular_velocity
    });
    // B relative to A, rad per step: the motor's unit and sign.
    let relative = (b - a) * sim.dt;
    assert!(
        (relative - motor.angular).abs() < 0.01 * motor.angular.abs(),
        "relative speed {relative} rad/step, target {}",
        motor.angular
    );
}

#[test]
fn a_scene_runs_and_its_step_counter_advances_with_play_pause_step_and_reset() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    h.get_by_label("stack of boxes").click();
    h.run_steps(10);
    // A selected scene is shown paused at step 0 (issue 64); Space plays it.
    assert_eq!(h.state().sim().unwrap().step_count(), 0);
    assert!(!h.state().is_running());
    h.key_press(Key::Space); // play
    h.run_steps(10);
    let steps = h.state().sim().unwrap().step_count();
    assert!(steps >= 5, "Space plays: {steps}");
    h.key_press(Key::Space); // pause
    h.run_steps(1);
    let paused = h.state().sim().unwrap().step_count();
    h.run_steps(10);
    assert_eq!(h.state().sim().unwrap().step_count(), paused);
    click(&mut h, "Step");
    assert_eq!(h.state().sim().unwrap().step_count(), paused + 1);
    h.get_by_label_contains(&format!("step {}", paused + 1));
    click(&mut h, "Reset");
    assert_eq!(h.state().sim().unwrap().step_count(), 0);
}

#[test]
fn undo_and_redo_round_trip_inspector_and_canvas_edits() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    let original = h.state().model().clone();
    h.get_by_label("stack of boxes").click();
    h.run_steps(2);
    type_into(&mut h, "gravitation", "50");
    assert_eq!(
        h.state()
            .model()
            .scene("stack of boxes")
            .unwrap()
            .gravitation,
        50.0
    );
    let edited = h.state().model().clone();
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run_steps(2);
    assert_eq!(*h.state().model(), original);
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    h.run_steps(2);
    assert_eq!(*h.state().model(), edited);
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run_steps(2);
    h.key_press_modifiers(Modifiers::COMMAND, Key::Y);
    h.run_steps(2);
    assert_eq!(*h.state().model(), edited);

    // Deleting a body that robots use is refused; a new, unused one goes and comes back.
    new_item(&mut h, "body");
    let with_body = h.state().model().clone();
    click(&mut h, "Delete");
    assert_eq!(h.state().model().bodies.len(), with_body.bodies.len() - 1);
    click(&mut h, "Undo");
    assert_eq!(*h.state().model(), with_body);
    click(&mut h, "Redo");
    assert_eq!(h.state().model().bodies.len(), with_body.bodies.len() - 1);
}

#[test]
fn dragging_and_turning_a_body_at_step_0_edits_its_placement_in_the_scene() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    h.get_by_label("stack of boxes").click();
    h.run_steps(2);
    click(&mut h, "Reset");
    let placement = |h: &Harness<'_, RoboSimApp>| {
        let scene = h.state().model().scene("stack of boxes").unwrap().clone();
        let b = scene
            .bodies
            .iter()
            .find(|b| b.alias == "box 1")
            .unwrap()
            .clone();
        (b.x, b.y, b.orientation)
    };
    assert_eq!(placement(&h), (400.0, 365.0, 0.0));
    // Grab box 1 (400, 365) a little off its origin and move it 60.2 to the right: the
    // grabbed point follows the pointer and the origin snaps to the 0.5 grid.
    drag_world(&mut h, (402.0, 366.0), (462.2, 366.0));
    let (x, y, o) = placement(&h);
    assert_eq!(
        (x, y, o),
        (460.0, 365.0, 0.0),
        "status: {}",
        h.state().status()
    );
    h.key_press(Key::E);
    h.run_steps(2);
    let (_, _, o) = placement(&h);
    assert!((o - 15f64.to_radians()).abs() < 1e-12, "orientation {o}");
    // One undo per gesture.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run_steps(2);
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run_steps(2);
    assert_eq!(placement(&h), (400.0, 365.0, 0.0));
}

/// Pauses the selected scene at step 0, where the canvas edits it.
/// Opens `scene` and resets it to step 0, where placements can be selected and edited.
fn open_at_step_0(h: &mut Harness<'_, RoboSimApp>, scene: &str) {
    h.get_by_label(scene).click();
    h.run_steps(2);
    stop_at_step_0(h);
}

fn stop_at_step_0(h: &mut Harness<'_, RoboSimApp>) {
    if h.state().is_running() {
        click(h, "Pause");
    }
    click(h, "Reset");
    assert_eq!(h.state().sim().unwrap().step_count(), 0);
}

#[test]
fn ctrl_s_saves_without_stepping_the_simulation() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    open_at_step_0(&mut h, "stack of boxes");
    type_into(&mut h, "gravitation", "150");
    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run_steps(2);
    assert!(!h.state().db().is_dirty(), "saved: {}", h.state().status());
    assert_eq!(
        h.state().sim().unwrap().step_count(),
        0,
        "saving leaves the scene at step 0, where it is edited"
    );
    // S alone still steps.
    h.key_press(Key::S);
    h.run_steps(2);
    assert_eq!(h.state().sim().unwrap().step_count(), 1);
}

/// Where simulated body `id_part` (a part of its trace id) has its reference point now.
fn body_origin(h: &Harness<'_, RoboSimApp>, id_part: &str) -> pe::Vec2 {
    let sim = h.state().sim().expect("a simulation");
    let b = sim
        .bodies
        .iter()
        .find(|b| b.id.contains(id_part))
        .unwrap_or_else(|| panic!("no body {id_part}"));
    sim.world.body(b.handle).unwrap().origin()
}

fn on_canvas(h: &Harness<'_, RoboSimApp>, p: pe::Vec2) -> bool {
    let app = h.state();
    app.canvas_rect()
        .contains(app.camera().to_screen(app.canvas_rect(), p))
}

#[test]
fn new_placements_land_in_free_space_in_view_and_a_drag_takes_the_body_on_top() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    new_item(&mut h, "scene");
    let Some(Selection::Scene(scene)) = h.state().selection().cloned() else {
        panic!()
    };
    click(&mut h, "+ body");
    click(&mut h, "floor");
    click(&mut h, "+ robot");
    click(&mut h, "car");
    h.run_steps(2);
    assert!(
        h.state().overlaps().is_empty(),
        "the car lands clear of the floor: {:?}",
        h.state().model().scene(&scene)
    );
    let chassis = body_origin(&h, "chassis");
    assert!(on_canvas(&h, chassis), "the car is in view at {chassis}");
    let floor = body_origin(&h, "floor");
    assert!(chassis.y < floor.y, "above the floor, not under it");

    // Dragged into the floor, the car is flagged; a second drag takes the car (drawn on
    // top, and selected), not the floor under it.
    drag_world(&mut h, (chassis.x, chassis.y), (floor.x, floor.y));
    assert!(!h.state().overlaps().is_empty(), "{}", h.state().status());
    h.get_by_label_contains("overlaps");
    let placed = |h: &Harness<'_, RoboSimApp>| {
        let s = h.state().model().scene(&scene).unwrap().clone();
        (
            (s.robots[0].x, s.robots[0].y),
            (s.bodies[0].x, s.bodies[0].y),
        )
    };
    let (_, floor_before) = placed(&h);
    let at = body_origin(&h, "chassis");
    drag_world(&mut h, (at.x, at.y), (at.x + 40.0, at.y - 200.0));
    let (car, floor_after) = placed(&h);
    assert_eq!(floor_after, floor_before, "the floor stays");
    assert!(car.1 < floor.y - 100.0, "the car moved up: {car:?}");
    assert!(h.state().overlaps().is_empty());
}

#[test]
fn the_default_scenes_have_no_overlaps_to_warn_about() {
    let (db, _) = Database::embedded();
    for scene in &db.model.scenes {
        let Ok(sim) = robosim::sim::Simulation::new(&db.model, &scene.name, None, None) else {
            continue;
        };
        let pairs = robosim::app::placing::overlapping_pairs(&sim);
        let named: Vec<(&str, &str)> = pairs
            .iter()
            .map(|&(a, b)| (sim.bodies[a].id.as_str(), sim.bodies[b].id.as_str()))
            .collect();
        assert!(named.is_empty(), "{}: {named:?}", scene.name);
    }
}

#[test]
fn a_vertex_drag_takes_the_vertex_where_the_button_went_down() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    new_item(&mut h, "body");
    let Some(Selection::Body(name)) = h.state().selection().cloned() else {
        panic!()
    };
    assert_eq!(
        h.state().model().body(&name).unwrap().vertices[1],
        [20.0, -10.0]
    );
    // Pressed 3 px off the vertex and moved briskly: by the time egui calls it a drag
    // the pointer is far from every vertex.
    let screen = |h: &Harness<'_, RoboSimApp>, x: f64, y: f64| {
        let app = h.state();
        app.camera()
            .to_screen(app.canvas_rect(), pe::Vec2::new(x, y))
            + egui::vec2(3.0, 3.0)
    };
    let (start, end) = (screen(&h, 20.0, -10.0), screen(&h, 30.0, -20.0));
    drag_screen(&mut h, start, end, 2);
    let vertices = h.state().model().body(&name).unwrap().vertices.clone();
    assert_eq!(vertices[1], [30.0, -20.0], "{}", h.state().status());
}

fn harness_with_autosave(dir: &Path, autosave: &Path) -> Harness<'static, RoboSimApp> {
    let app = RoboSimApp::new(Some(dir.to_path_buf())).with_autosave(Some(autosave.to_path_buf()));
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(move |_| app);
    h.run_steps(3);
    h
}

#[test]
fn unsaved_work_is_kept_soon_after_an_edit_and_offered_back_only_for_its_folder() {
    let (folder_a, folder_b) = (scratch_db(), scratch_db());
    let autosave = tempfile::tempdir().unwrap();
    {
        let mut h = harness_with_autosave(folder_a.path(), autosave.path());
        h.get_by_label("stack of boxes").click();
        h.run_steps(2);
        type_into(&mut h, "gravitation", "123");
        // The app sits idle for three seconds; then it is killed (no exit hook runs).
        h.run_steps(180);
    }
    let h = harness_with_autosave(folder_b.path(), autosave.path());
    assert!(
        h.query_by_label_contains("Restore it?").is_none(),
        "work on another folder is not offered here"
    );
    let mut h = harness_with_autosave(folder_a.path(), autosave.path());
    h.get_by_label_contains("Restore it?");
    click(&mut h, "Restore");
    let g = h
        .state()
        .model()
        .scene("stack of boxes")
        .unwrap()
        .gravitation;
    assert_eq!(g, 123.0, "the edit made before the kill is back");
}

#[test]
fn the_view_comes_back_with_fit_and_reset_and_the_car_demo_stops_at_the_edge_of_the_world() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    h.get_by_label("car on terrain").click();
    h.run_steps(3);
    // Panned far away, F brings the car back; so does Reset.
    for key in [Key::F, Key::R] {
        h.state_mut().camera_mut().centre += pe::Vec2::new(5e4, 5e4);
        h.run_steps(1);
        assert!(!on_canvas(&h, body_origin(&h, "chassis")));
        h.key_press(key);
        h.run_steps(2);
        assert!(
            on_canvas(&h, body_origin(&h, "chassis")),
            "{key:?} fits the view"
        );
    }
    // The car drives off the end of its terrain after about 17 s. Run 60 s at 8×.
    if !h.state().is_running() {
        click(&mut h, "Play");
    }
    h.state_mut().set_speed(8.0);
    for _ in 0..600 {
        h.run_steps(1);
        if h.state().sim().unwrap().time() > 60.0 || !h.state().is_running() {
            break;
        }
    }
    let app = h.state();
    let sim = app.sim().unwrap();
    let m = sim.metrics();
    assert!(m.time > 17.0, "{m:?}");
    assert!(m.kinetic < 1e-6, "everything stopped: {m:?}");
    let bound = app.world_bound().unwrap();
    // Stopped in the step that carried it over the edge: at most one step's fall beyond,
    // from the top of the scene (8 px when the car falls off its terrain).
    let g = sim.world.gravity.norm();
    let one_step = (2.0 * g * (bound.limit.max.y - bound.scene.min.y)).sqrt() * sim.dt;
    for (_, b) in sim.world.bodies() {
        let c = b.centroid();
        assert!(
            c.y <= bound.limit.max.y + one_step,
            "stopped at the edge: {c} (edge {:?})",
            bound.limit
        );
    }
    assert!(app.status().contains("left the scene"), "{}", app.status());
    assert!(!app.is_running(), "paused once nothing moves");
    h.run_steps(3);
    assert!(
        on_canvas(&h, body_origin(&h, "floor")),
        "the scene is back in view"
    );
    // And so is the car where it was stopped (issue 64: it ended out of view).
    assert!(
        on_canvas(&h, body_origin(&h, "chassis")),
        "the stopped car is in view"
    );
}

#[test]
fn plots_show_one_unit_per_axis_with_readable_numbers_and_export_to_csv() {
    use robosim::app::files::{Answer, Scripted};
    use robosim::app::plots::number_at_step;
    // Tick numbers keep the digits their spacing needs, in scientific notation when large.
    assert_eq!(number_at_step(2.5e7, 5e6), "2.5e7");
    assert_eq!(number_at_step(0.25, 0.05), "0.25");
    assert_eq!(number_at_step(3e-9, 1e-9), "3e-9");
    assert_eq!(number_at_step(1200.0, 100.0), "1200");

    let dir = scratch_db();
    let csv = dir.path().join("exported.csv");
    let app = RoboSimApp::new(Some(dir.path().to_path_buf()))
        .with_file_chooser(Box::new(Scripted::new([Answer::Chosen(csv.clone())])));
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(move |_| app);
    h.run_steps(3);
    h.get_by_label("car on terrain").click();
    h.run_steps(2);
    click(&mut h, "Play");
    let chassis = body_origin(&h, "chassis");
    click_world(&mut h, chassis.x, chassis.y, Modifiers::NONE);
    h.run_steps(20);
    // The body plot shows one quantity, in its unit, chosen from a list.
    h.get_by_value("position x, y (px)").click();
    h.run_steps(2);
    h.get_by_label("angular velocity ω (rad/s)").click();
    h.run_steps(2);
    h.get_by_value("angular velocity ω (rad/s)");
    h.get_by_value("motor torques (mass·px²/s²)");

    click(&mut h, "Pause");
    click(&mut h, "Export CSV…");
    let text = std::fs::read_to_string(&csv).expect("the CSV was written");
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("time (s),kinetic energy"), "{header}");
    assert!(header.contains("body ω (rad/s)") && header.contains("torque car#0/"));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), h.state().plot_data().samples.len());
    assert!(rows.len() > 10);
    let columns = header.split(',').count();
    for row in &rows {
        assert_eq!(row.split(',').count(), columns, "{row}");
        row.split(',').next().unwrap().parse::<f64>().unwrap();
    }
    // The energies as the energy plot shows them (issue 64): potential and total since
    // step 0, total = kinetic + potential change - kinetic at step 0.
    assert!(
        header.contains("potential energy since step 0")
            && header.contains("total energy since step 0"),
        "{header}"
    );
    let numbers =
        |row: &str| -> Vec<f64> { row.split(',').take(4).map(|v| v.parse().unwrap()).collect() };
    let first = numbers(rows[0]);
    assert_eq!(
        (first[2], first[3]),
        (0.0, 0.0),
        "nothing changed at step 0"
    );
    let last = numbers(rows[rows.len() - 1]);
    assert!((last[3] - (last[1] + last[2] - first[1])).abs() <= 1e-9 * last[1].abs().max(1.0));
    assert!(
        h.state().status().contains("plots written"),
        "{}",
        h.state().status()
    );
    // Every joint's angle and spin (issue 65): the car's wheels turn forward against the
    // chassis, clockwise on screen, at up to their motors' 6 rad/s.
    let column = |name: &str| header.split(',').position(|h| h == name).expect(name);
    let spin = column("spin car#0/chassis-rear (rad/s)");
    column("angle car#0/chassis-rear (rad)");
    let last_spin: f64 = rows[rows.len() - 1]
        .split(',')
        .nth(spin)
        .unwrap()
        .parse()
        .unwrap();
    assert!(last_spin > 0.5 && last_spin <= 6.0 + 1e-6, "{last_spin}");
}

#[test]
fn saving_a_non_convex_body_asks_first_and_says_what_the_simulation_will_do() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    new_item(&mut h, "body");
    let Some(Selection::Body(name)) = h.state().selection().cloned() else {
        panic!()
    };
    // A dent: Shift+click takes a vertex inside the outline.
    click_world(&mut h, 0.0, -5.0, Modifiers::SHIFT);
    assert_eq!(h.state().model().body(&name).unwrap().vertices.len(), 5);
    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run_steps(2);
    assert!(
        h.state().db().is_dirty(),
        "not saved before the user answers"
    );
    h.get_by_label_contains("not a convex polygon");
    h.get_by_label_contains("will not run");
    click(&mut h, "Cancel");
    assert!(h.state().db().is_dirty());
    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run_steps(2);
    click(&mut h, "Save anyway");
    assert!(!h.state().db().is_dirty(), "{}", h.state().status());
    let (saved, _) = Database::load(dir.path());
    assert_eq!(saved.model.body(&name).unwrap().vertices.len(), 5);
}

#[test]
fn a_db_folder_that_does_not_exist_is_asked_about_not_opened_silently() {
    let parent = tempfile::tempdir().unwrap();
    let missing = parent.path().join("no such folder");
    let mut h = harness(&missing);
    h.get_by_label_contains("does not exist");
    // Nothing shown, nothing running: the toolbar offers Play, not Pause.
    assert!(!h.state().is_running() && h.query_by_label("Pause").is_none());
    click(&mut h, "Open the examples instead");
    assert!(h.state().db().dir.is_none());
    assert!(!h.state().model().scenes.is_empty(), "the examples");
    assert!(!missing.exists(), "nothing was created");

    let mut h = harness(&missing);
    click(&mut h, "Start a new database there");
    assert_eq!(h.state().db().dir.as_deref(), Some(missing.as_path()));
    assert!(h.state().model().bodies.is_empty());
}

#[test]
fn a_refused_rename_shows_the_current_name_again() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    h.get_by_label("stack of boxes").click();
    h.run_steps(2);
    type_into(&mut h, "name", "car on terrain");
    assert!(
        h.state().status().contains("cannot rename"),
        "{}",
        h.state().status()
    );
    h.run_steps(2);
    assert_eq!(
        h.get_by_label("name").value().as_deref(),
        Some("stack of boxes"),
        "the field shows the name the scene still has"
    );
}

#[test]
fn a_record_that_could_not_be_read_stays_in_the_problems_after_an_unrelated_edit() {
    let dir = scratch_db();
    let bodies = dir.path().join("bodies.xml");
    let text = std::fs::read_to_string(&bodies).unwrap().replace(
        r#"<body name="wheel" density="1""#,
        r#"<body name="wheel" density="heavy""#,
    );
    std::fs::write(&bodies, text).unwrap();
    let mut h = harness(dir.path());
    let cause = |h: &Harness<'_, RoboSimApp>| {
        h.state()
            .problems()
            .iter()
            .any(|p| p.to_string().contains("heavy"))
    };
    assert!(cause(&h), "{:#?}", h.state().problems());
    h.get_by_label("stack of boxes").click();
    h.run_steps(2);
    type_into(&mut h, "gravitation", "150");
    assert!(
        cause(&h),
        "the root cause stays: {:#?}",
        h.state().problems()
    );
}

#[test]
fn placements_copy_paste_and_turn_by_their_handle_and_the_view_exports_as_svg() {
    use robosim::app::files::{Answer, Scripted};
    let dir = scratch_db();
    let svg = dir.path().join("view.svg");
    let app = RoboSimApp::new(Some(dir.path().to_path_buf()))
        .with_file_chooser(Box::new(Scripted::new([Answer::Chosen(svg.clone())])));
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(move |_| app);
    h.run_steps(3);
    open_at_step_0(&mut h, "stack of boxes");
    let scene =
        |h: &Harness<'_, RoboSimApp>| h.state().model().scene("stack of boxes").unwrap().clone();
    let count = scene(&h).bodies.len();
    click_world(&mut h, 400.0, 365.0, Modifiers::NONE);
    h.key_press_modifiers(Modifiers::COMMAND, Key::C);
    h.run_steps(1);
    h.key_press_modifiers(Modifiers::COMMAND, Key::V);
    h.run_steps(2);
    let pasted = scene(&h);
    assert_eq!(pasted.bodies.len(), count + 1, "{}", h.state().status());
    assert_eq!(pasted.bodies[count].alias, "box 9");
    assert!(h.state().overlaps().is_empty(), "pasted in free space");

    // The handle above the selected box turns it: dragged from straight above the origin
    // to straight right of it, a quarter turn clockwise on screen.
    click_world(&mut h, 400.0, 365.0, Modifiers::NONE);
    let app = h.state();
    let sim = app.sim().unwrap();
    let i = app.followed().expect("box 1 is selected");
    let body = sim.world.body(sim.bodies[i].handle).unwrap();
    let origin = app.camera().to_screen(app.canvas_rect(), body.origin());
    let top = body
        .world_vertices()
        .map(|v| app.camera().to_screen(app.canvas_rect(), v).y)
        .fold(f32::INFINITY, f32::min);
    let handle = egui::pos2(origin.x, top - 24.0);
    let right = origin + egui::vec2(origin.y - handle.y, 0.0);
    drag_screen(&mut h, handle, right, 6);
    let turned = scene(&h)
        .bodies
        .iter()
        .find(|b| b.alias == "box 1")
        .unwrap()
        .clone();
    assert!(
        (turned.orientation - std::f64::consts::FRAC_PI_2).abs() < 1e-6,
        "orientation {}",
        turned.orientation
    );
    assert_eq!(
        (turned.x, turned.y),
        (400.0, 365.0),
        "turned about its origin"
    );

    h.get_by_label("File").click();
    h.run_steps(2);
    click(&mut h, "Export view as SVG…");
    let text = std::fs::read_to_string(&svg).expect("the view was written");
    assert!(text.starts_with("<svg") && text.matches("<polygon").count() > count);

    h.key_press(Key::F1);
    h.run_steps(2);
    h.get_by_label_contains("Back to step 0");
}

// More of the editor's tests, a file per feature.
#[path = "editor/chooser.rs"]
mod chooser;
#[path = "editor/drawing.rs"]
mod drawing;
#[path = "editor/export.rs"]
mod export;
#[path = "editor/new_user.rs"]
mod new_user;
#[path = "editor/running.rs"]
mod running;
#[path = "editor/selection.rs"]
mod selection;

/// (issue 64).
#[test]
fn f1_and_esc_close_the_shortcut_sheet_and_help_opens_the_guide() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    let sheet_open = |h: &Harness<'_, RoboSimApp>| h.query_by_label("This list").is_some();
    assert!(!sheet_open(&h));
    for close in [Key::F1, Key::Escape] {
        h.key_press(Key::F1);
        h.run_steps(2);
        assert!(sheet_open(&h), "F1 opens the sheet");
        h.key_press(close);
        h.run_steps(2);
        assert!(!sheet_open(&h), "{close:?} closes it");
    }
    click(&mut h, "Help");
    click(&mut h, "User guide");
    h.run_steps(2);
    assert!(
        h.query_by_label_contains("RoboSim edits and simulates")
            .is_some()
    );
    // Its Markdown drawn, not shown as typed (`**Menu bar and toolbar**`).
    assert!(h.query_by_label_contains("Menu bar and toolbar").is_some());
    assert!(
        h.query_by_label_contains("**").is_none(),
        "raw Markdown shown"
    );
}

/// The inspector keeps its width when a joint with a motor is opened (issue 64: the
/// motor's direction said in words, "rear leg clockwise against body", widened it past
/// the window's edge; an arrow says it now, the words on hover).
#[test]
fn the_inspector_keeps_its_width_when_a_joint_is_opened() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    h.get_by_label("walker · 3 bodies, 2 joints").click();
    h.run_steps(3);
    let canvas = h.state().canvas_rect().width();
    h.get_by_label("body – rear leg").click();
    h.run_steps(3);
    assert_eq!(
        h.query_all_by_label("swing period").count(),
        1,
        "its motor shown"
    );
    assert_eq!(
        h.state().canvas_rect().width(),
        canvas,
        "the canvas beside the inspector kept its width"
    );
}
