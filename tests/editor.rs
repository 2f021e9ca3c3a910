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

/// Clicks the canvas at world point (x, y).
fn click_world(h: &mut Harness<'_, RoboSimApp>, x: f64, y: f64, modifiers: Modifiers) {
    let app = h.state();
    let pos: Pos2 = app.camera.to_screen(app.canvas_rect, pe::Vec2::new(x, y));
    assert!(
        app.canvas_rect.contains(pos),
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
    let app = h.state();
    let screen = |(x, y): (f64, f64)| app.camera.to_screen(app.canvas_rect, pe::Vec2::new(x, y));
    let (start, end) = (screen(from), screen(to));
    h.event(Event::PointerMoved(start));
    h.run_steps(1);
    let button = |pos, pressed| Event::PointerButton {
        pos,
        button: PointerButton::Primary,
        pressed,
        modifiers: Modifiers::NONE,
    };
    h.event(button(start, true));
    h.run_steps(1);
    for k in 1..=4 {
        h.event(Event::PointerMoved(
            start + (end - start) * (k as f32 / 4.0),
        ));
        h.run_steps(1);
    }
    h.event(button(end, false));
    h.run_steps(2);
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

#[test]
fn a_body_drawn_by_clicks_is_saved_and_found_again() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    new_item(&mut h, "body");
    let name = match &h.state().selection {
        Some(Selection::Body(name)) => name.clone(),
        other => panic!("a new body is selected, not {other:?}"),
    };
    click(&mut h, "Clear and draw");
    assert!(h.state().db.model.body(&name).unwrap().vertices.is_empty());
    for (x, y) in [(-15.0, -10.0), (15.0, -10.0), (15.0, 10.0), (-15.0, 10.0)] {
        click_world(&mut h, x, y, Modifiers::NONE);
    }
    let body = h.state().db.model.body(&name).unwrap().clone();
    assert_eq!(
        body.vertices,
        vec![[-15.0, -10.0], [15.0, -10.0], [15.0, 10.0], [-15.0, 10.0]]
    );
    type_into(&mut h, "density", "2.5");
    assert_eq!(h.state().db.model.body(&name).unwrap().density, 2.5);

    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run_steps(2);
    assert!(!h.state().db.is_dirty(), "saved: {}", h.state().status);
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
    let Some(Selection::Body(name)) = h.state().selection.clone() else {
        panic!()
    };
    click(&mut h, "Clear and draw");
    for (x, y) in [(-20.0, -20.0), (20.0, -20.0), (0.0, 20.0)] {
        click_world(&mut h, x, y, Modifiers::NONE);
    }
    let triangle = h.state().db.model.body(&name).unwrap().vertices.clone();
    assert_eq!(triangle.len(), 3);
    // Inside the triangle: no edge can take it and stay convex.
    click_world(&mut h, 0.0, -5.0, Modifiers::NONE);
    assert_eq!(h.state().db.model.body(&name).unwrap().vertices, triangle);
    assert!(
        h.state().status.contains("non-convex"),
        "status: {}",
        h.state().status
    );
    h.get_by_label_contains("non-convex");
    // Shift+click takes it anyway; the outline is then flagged invalid until repaired.
    click_world(&mut h, 0.0, -5.0, Modifiers::SHIFT);
    assert_eq!(h.state().db.model.body(&name).unwrap().vertices.len(), 4);
    assert!(
        h.state()
            .problems
            .iter()
            .any(|p| p.is_error() && p.to_string().contains(&name))
    );
    click(&mut h, "Convex hull");
    assert_eq!(h.state().db.model.body(&name).unwrap().vertices.len(), 3);
    assert!(!h.state().problems.iter().any(|p| p.is_error()));
}

#[test]
fn a_two_body_robot_with_a_joint_and_a_motor_simulates() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    new_item(&mut h, "robot");
    let Some(Selection::Robot(name)) = h.state().selection.clone() else {
        panic!()
    };
    for _ in 0..2 {
        click(&mut h, "+ body");
        click(&mut h, "obdelnik");
    }
    let robot = h.state().db.model.robot(&name).unwrap().clone();
    assert_eq!(robot.bodies.len(), 2);
    // obdelnik is 40 wide: the second body sits 30 to the right, overlapping by 10.
    assert_eq!(
        (robot.bodies[1].placement.x, robot.bodies[1].placement.y),
        (30.0, 0.0)
    );
    assert!(
        h.state()
            .problems
            .iter()
            .any(|p| p.to_string().contains("connected")),
        "two loose bodies are flagged live"
    );

    click(&mut h, "Add joint");
    click_world(&mut h, 5.0, 30.0, Modifiers::NONE); // outside both
    assert!(
        h.state().status.contains("covered by 0"),
        "{}",
        h.state().status
    );
    click_world(&mut h, 15.0, 0.0, Modifiers::NONE);
    let robot = h.state().db.model.robot(&name).unwrap().clone();
    assert_eq!(robot.joints.len(), 1, "{}", h.state().status);
    let j = &robot.joints[0];
    assert_eq!(
        (j.body_a.as_str(), j.body_b.as_str()),
        ("obdelnik", "obdelnik 2")
    );
    assert_eq!((j.anchor_ax, j.anchor_ay), (15.0, 0.0));
    assert!(
        !h.state()
            .problems
            .iter()
            .any(|p| p.to_string().contains("connected"))
    );

    click(&mut h, "Add joint"); // back to selecting
    h.get_by_label_contains("obdelnik – obdelnik 2").click();
    h.run_steps(2);
    click(&mut h, "joint motor");
    let motor = h.state().db.model.robot(&name).unwrap().joints[0]
        .motor
        .clone();
    let motor = motor.expect("the joint has a motor");
    assert!(motor.max_torque > 0.0 && motor.angular != 0.0);

    // Run the robot preview: the motor turns body A against body B about the pin.
    click(&mut h, "Play");
    h.run_steps(30);
    let sim = h.state().sim.as_ref().unwrap();
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
    let relative = (a - b) * sim.dt; // rad per step, the motor's unit
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
    let steps = h.state().sim.as_ref().unwrap().step_count();
    assert!(steps >= 5, "a selected scene plays: {steps}");
    h.key_press(Key::Space); // pause
    h.run_steps(1);
    let paused = h.state().sim.as_ref().unwrap().step_count();
    h.run_steps(10);
    assert_eq!(h.state().sim.as_ref().unwrap().step_count(), paused);
    click(&mut h, "Step");
    assert_eq!(h.state().sim.as_ref().unwrap().step_count(), paused + 1);
    h.get_by_label_contains(&format!("step {}", paused + 1));
    click(&mut h, "Reset");
    assert_eq!(h.state().sim.as_ref().unwrap().step_count(), 0);
}

#[test]
fn undo_and_redo_round_trip_inspector_and_canvas_edits() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    let original = h.state().db.model.clone();
    h.get_by_label("stack of boxes").click();
    h.run_steps(2);
    type_into(&mut h, "gravitation", "50");
    assert_eq!(
        h.state()
            .db
            .model
            .scene("stack of boxes")
            .unwrap()
            .gravitation,
        50.0
    );
    let edited = h.state().db.model.clone();
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run_steps(2);
    assert_eq!(h.state().db.model, original);
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    h.run_steps(2);
    assert_eq!(h.state().db.model, edited);
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run_steps(2);
    h.key_press_modifiers(Modifiers::COMMAND, Key::Y);
    h.run_steps(2);
    assert_eq!(h.state().db.model, edited);

    // Deleting a body that robots use is refused; a new, unused one goes and comes back.
    new_item(&mut h, "body");
    let with_body = h.state().db.model.clone();
    click(&mut h, "Delete");
    assert_eq!(h.state().db.model.bodies.len(), with_body.bodies.len() - 1);
    click(&mut h, "Undo");
    assert_eq!(h.state().db.model, with_body);
    click(&mut h, "Redo");
    assert_eq!(h.state().db.model.bodies.len(), with_body.bodies.len() - 1);
}

#[test]
fn dragging_and_turning_a_body_at_step_0_edits_its_placement_in_the_scene() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    h.get_by_label("stack of boxes").click();
    h.run_steps(2);
    click(&mut h, "Pause");
    click(&mut h, "Reset");
    let placement = |h: &Harness<'_, RoboSimApp>| {
        let scene = h.state().db.model.scene("stack of boxes").unwrap().clone();
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
        h.state().status
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
