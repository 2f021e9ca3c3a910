//! A new user's first robot, the whole way (issue 64): an empty folder; a chassis, a
//! wheel and a floor drawn; a car with snapped axles and motors that drive it forward;
//! pulled by the mouse while Follow is on; turned by its handle; copied and pasted with
//! Ctrl+C and Ctrl+V; saved into a new folder on a machine with no file dialog; reopened
//! as it was built.

use super::chooser::retype;
use super::{
    body_origin, click, click_world, drag_world, harness, harness_with_files, new_item,
    press_and_move, release, stop_at_step_0, type_into,
};
use egui::{Modifiers, Pos2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use robosim::app::files::{Answer, Scripted};
use robosim::app::{RoboSimApp, Selection};
use robosim::db::Database;

fn new_body(h: &mut Harness<'_, RoboSimApp>, name: &str) {
    new_item(h, "body");
    type_into(h, "name", name);
    assert!(
        h.state().model().body(name).is_some(),
        "{}",
        h.state().status()
    );
}

/// The rover's placement in the scene: its origin and orientation.
fn rover_placement(h: &Harness<'_, RoboSimApp>, k: usize) -> (f64, f64, f64) {
    let scene = h.state().model().scene("proving ground").unwrap();
    let r = &scene.robots[k];
    (r.x, r.y, r.orientation)
}

/// The screen point of world point `p`.
fn screen(h: &Harness<'_, RoboSimApp>, p: pe::Vec2) -> Pos2 {
    h.state().camera().to_screen(h.state().canvas_rect(), p)
}

/// Drags the rotate handle of the selection `sweep` degrees about the chassis's origin
/// in `moves` moves.
fn turn_by_handle(h: &mut Harness<'_, RoboSimApp>, sweep: f32, moves: usize) {
    let origin = screen(h, body_origin(h, "rover#0/chassis"));
    let top = {
        let app = h.state();
        let sim = app.sim().unwrap();
        app.picked()
            .iter()
            .flat_map(|&i| {
                let body = sim.world.body(sim.bodies[i].handle).unwrap();
                body.world_vertices().collect::<Vec<_>>()
            })
            .map(|v| app.camera().to_screen(app.canvas_rect(), v).y)
            .fold(f32::INFINITY, f32::min)
    };
    // The handle stands 24 points above the selection, over the chassis's origin.
    let handle = egui::pos2(origin.x, top - 24.0);
    super::sweep_handle(h, origin, handle, sweep, moves);
}

#[test]
fn a_new_user_builds_a_car_drives_it_turns_copies_and_saves_it_without_a_file_dialog() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness_with_files(dir.path(), Scripted::new([Answer::Unavailable]));
    assert!(
        h.state().model().bodies.is_empty(),
        "an empty folder, an empty database"
    );

    // A chassis drawn by clicks, a hexagonal wheel and a static floor from the shape tools.
    new_body(&mut h, "chassis");
    click(&mut h, "Clear and draw");
    for (x, y) in [(-40.0, -10.0), (40.0, -10.0), (40.0, 10.0), (-40.0, 10.0)] {
        click_world(&mut h, x, y, Modifiers::NONE);
    }
    new_body(&mut h, "wheel");
    type_into(&mut h, "r", "18");
    click(&mut h, "Regular polygon");
    new_body(&mut h, "floor");
    type_into(&mut h, "w", "1200");
    type_into(&mut h, "h", "20");
    click(&mut h, "Rectangle");
    type_into(&mut h, "density", "0");
    let m = h.state().model().clone();
    assert_eq!(m.body("chassis").unwrap().vertices.len(), 4);
    assert_eq!(m.body("wheel").unwrap().vertices.len(), 6);
    assert_eq!(m.body("floor").unwrap().vertices[2], [600.0, 10.0]);
    assert_eq!(m.body("floor").unwrap().density, 0.0);

    // The robot: the chassis, two wheels dragged under its ends.
    new_item(&mut h, "robot");
    type_into(&mut h, "name", "rover");
    for body in ["chassis", "wheel", "wheel"] {
        click(&mut h, "+ body");
        click(&mut h, body);
    }
    let placed = |h: &Harness<'_, RoboSimApp>, k: usize| {
        let b = &h.state().model().robot("rover").unwrap().bodies[k].placement;
        (b.x, b.y)
    };
    let (x2, y2) = placed(&h, 2);
    drag_world(&mut h, (x2, y2), (30.0, 5.0));
    let (x1, y1) = placed(&h, 1);
    drag_world(&mut h, (x1, y1), (-30.0, 5.0));
    assert_eq!((placed(&h, 1), placed(&h, 2)), ((-30.0, 5.0), (30.0, 5.0)));

    // Axles: clicks a little off each wheel's centre pin it at the centre.
    click(&mut h, "Add joint");
    click_world(&mut h, -29.6, 5.4, Modifiers::NONE);
    click_world(&mut h, 30.4, 4.6, Modifiers::NONE);
    click(&mut h, "Add joint");
    let robot = h.state().model().robot("rover").unwrap().clone();
    assert_eq!(robot.joints.len(), 2, "{}", h.state().status());
    let pins: Vec<[f64; 2]> = robot
        .joints
        .iter()
        .map(|j| {
            let a = robot.bodies.iter().find(|b| b.placement.alias == j.body_a);
            j.point(&a.unwrap().placement)
        })
        .collect();
    assert_eq!(
        pins,
        [[-30.0, 5.0], [30.0, 5.0]],
        "snapped to the wheels' centres"
    );

    // Motors with their defaults.
    // Each joint opened, its motor switched on, and closed again (open, its fields push
    // the next one out of view).
    for header in ["chassis – wheel", "chassis – wheel 2"] {
        h.get_by_label(header).click();
        h.run_steps(2);
        h.get_by_label("joint motor").click();
        h.run_steps(2);
        h.get_by_label(header).click();
        h.run_steps(2);
    }
    let robot = h.state().model().robot("rover").unwrap().clone();
    assert!(robot.joints.iter().all(|j| j.motor.is_some()), "{robot:#?}");

    // The scene: the floor, the rover dropped over it. Shown paused; Play drives it
    // forward (to the right: positive motor speeds turn the wheels clockwise).
    new_item(&mut h, "scene");
    type_into(&mut h, "name", "proving ground");
    click(&mut h, "+ body");
    click(&mut h, "floor");
    click(&mut h, "+ robot");
    click(&mut h, "rover");
    assert!(h.state().overlaps().is_empty());
    assert_eq!(h.state().sim().unwrap().step_count(), 0, "shown paused");
    let start = body_origin(&h, "rover#0/chassis");
    click(&mut h, "Play");
    for _ in 0..600 {
        h.run_steps(1);
        if body_origin(&h, "rover#0/chassis").x - start.x > 40.0 {
            break;
        }
    }
    let moved = body_origin(&h, "rover#0/chassis") - start;
    assert!(moved.x > 40.0, "the rover drove forward: {moved}");
    assert!(
        h.state().sim().unwrap().metrics().max_joint_gap < 0.5,
        "its pins hold"
    );

    // Pulled up by the mouse while Follow is on (the default), it stays by the pointer.
    let grabbed = body_origin(&h, "rover#0/chassis");
    let wanted = pe::Vec2::new(grabbed.x, grabbed.y - 50.0);
    let (from, to) = (screen(&h, grabbed), screen(&h, wanted));
    press_and_move(&mut h, from, to, 6, Modifiers::NONE);
    for _ in 0..90 {
        h.run_steps(1);
    }
    let held = body_origin(&h, "rover#0/chassis");
    assert!(
        (held - wanted).norm() < 40.0,
        "the pulled chassis is at {held}, the pointer at {wanted}"
    );
    release(&mut h, to, Modifiers::NONE);

    // Back to step 0; the rover turned by its handle 30° and back.
    stop_at_step_0(&mut h);
    let chassis = body_origin(&h, "rover#0/chassis");
    click_world(&mut h, chassis.x, chassis.y, Modifiers::NONE);
    assert_eq!(h.state().picked().len(), 3, "the whole rover is picked");
    let before = rover_placement(&h, 0).2;
    turn_by_handle(&mut h, 30.0, 6);
    let turned = rover_placement(&h, 0).2 - before;
    assert!(
        (turned - 30f64.to_radians()).abs() < 0.5f64.to_radians(),
        "a 30° sweep turned the rover {}°",
        turned.to_degrees()
    );
    // A drag from the handle is no rubber band: it drew one, and its release picked what
    // the band touched (here nothing).
    assert_eq!(h.state().picked().len(), 3, "the sweep kept the selection");
    turn_by_handle(&mut h, -30.0, 6);
    let back = rover_placement(&h, 0).2 - before;
    assert!(
        back.abs() < 0.5f64.to_radians(),
        "turned back: {}°",
        back.to_degrees()
    );

    // Ctrl+C puts the rover on the clipboard as text; Ctrl+V pastes it in free space.
    let copied = super::copy_to_clipboard(&mut h);
    h.run_steps(1);
    h.event(egui::Event::Paste(copied));
    h.run_steps(2);
    let scene = h.state().model().scene("proving ground").unwrap().clone();
    assert_eq!(scene.robots.len(), 2, "{}", h.state().status());
    assert_eq!(scene.robots[1].source, "rover");
    assert!(h.state().overlaps().is_empty(), "pasted clear of the first");

    // Save As on a machine with no file dialog: the app's own chooser makes the folder.
    click(&mut h, "File");
    h.get_by_label_contains("Save As").click();
    h.run_steps(4);
    retype(&mut h, "new database", "garage");
    click(&mut h, "New Folder");
    click(&mut h, "Choose this folder");
    h.run_steps(2);
    let garage = dir.path().join("garage");
    assert_eq!(h.state().db().dir.as_deref(), Some(garage.as_path()));
    assert!(!h.state().db().is_dirty(), "saved: {}", h.state().status());

    // Reopened, everything is as it was built.
    let built = h.state().model().clone();
    let (reloaded, problems) = Database::load(&garage);
    assert!(problems.is_empty(), "{problems:#?}");
    assert_eq!(
        reloaded.model, built,
        "everything comes back as it was built"
    );
    let h = harness(&garage);
    assert_eq!(*h.state().model(), built);
    assert_eq!(
        h.state().selection(),
        Some(&Selection::Scene("proving ground".into()))
    );
}
