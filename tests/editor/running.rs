//! A scene as it runs: pulling bodies, the plots, the solver, live edits, scrubbing
//! back, Follow, previews and the edits that must restart a run (issue 64).

use super::{
    click, click_world, harness, open_at_step_0, press_and_move, release, scratch_db, type_into,
};
use egui::{Event, Key, Modifiers};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use robosim::app::{RoboSimApp, Selection};

/// A body pulled by the mouse while the scene runs and Follow is on (the default) goes
/// where the pointer is and stays near it (issue 64): the view followed the pulled body,
/// so the world point under a still pointer moved with it and the pull never let up; a
/// box of the stack reached x = 1389, y = -715 in 2 s.
#[test]
fn a_body_pulled_while_following_stays_by_the_pointer() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    open_at_step_0(&mut h, "stack of boxes");
    click(&mut h, "Play");
    h.run_steps(5);
    // Box 5, the top one (30 x 30 at x = 400, y = 245 as placed), pulled 60 to the right
    // and held there for two seconds of frames.
    let (start, target, wanted) = {
        let app = h.state();
        let sim = app.sim().unwrap();
        let top = sim.bodies.iter().find(|b| b.id == "box 5").unwrap();
        let p = sim.world.body(top.handle).unwrap().position;
        let screen = |x: f64, y: f64| {
            app.camera()
                .to_screen(app.canvas_rect(), pe::Vec2::new(x, y))
        };
        let wanted = pe::Vec2::new(p.x + 60.0, p.y);
        (screen(p.x, p.y), screen(wanted.x, wanted.y), wanted)
    };
    press_and_move(&mut h, start, target, 6, Modifiers::NONE);
    let steps_before = h.state().sim().unwrap().step_count();
    for _ in 0..120 {
        h.run_steps(1);
    }
    let app = h.state();
    let sim = app.sim().unwrap();
    assert!(
        sim.step_count() > steps_before + 20,
        "the scene ran while held"
    );
    let top = sim.bodies.iter().find(|b| b.id == "box 5").unwrap();
    let p = sim.world.body(top.handle).unwrap().position;
    // Where the pointer was put, in the world; the view holds still while the box is held
    // (it eased a few frames before the drag was recognised), so the pointer is still
    // about there. Before: the box 1,350 away, the pointer with it.
    let pointer = app.camera().to_world(app.canvas_rect(), target);
    assert!(
        (p - wanted).norm() < 40.0 && (pointer - wanted).norm() < 15.0,
        "the pulled box is at ({:.0}, {:.0}), the pointer at ({:.0}, {:.0}), put at ({:.0}, {:.0})",
        p.x,
        p.y,
        pointer.x,
        pointer.y,
        wanted.x,
        wanted.y
    );
    release(&mut h, target, Modifiers::NONE);
}

/// Choosing another body while a scene runs changes what the plots show, not what they
/// recorded (issue 64): every series goes on from step 0, the new body's included.
#[test]
fn choosing_another_body_keeps_every_plot_series_from_step_0() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    open_at_step_0(&mut h, "stack of boxes");
    click(&mut h, "Play");
    h.run_steps(30);
    let recorded = h.state().plot_data().samples.len();
    assert!(recorded > 10, "{recorded} samples");
    // Box 1 (the bottom one), then box 5, where they are now (the view held still, so
    // that the click lands where it was aimed).
    click(&mut h, "Follow");
    for id in ["box 1", "box 5"] {
        let app = h.state();
        let sim = app.sim().unwrap();
        let body = sim.bodies.iter().find(|b| b.id == id).unwrap();
        let at = sim.world.body(body.handle).unwrap().position;
        click_world(&mut h, at.x, at.y, Modifiers::NONE);
    }
    h.run_steps(5);
    let app = h.state();
    let data = app.plot_data();
    let sim = app.sim().unwrap();
    let shown = data.shown_body.expect("a body is shown");
    assert_eq!(sim.bodies[shown].id, "box 5");
    assert!(data.samples.len() > recorded, "the series went on");
    assert_eq!(data.samples[0].time, 0.0, "from step 0");
    assert!(
        data.samples.iter().all(|s| data.shown_state(s).is_some()),
        "box 5's series from step 0"
    );
}

/// The toolbar's solver is the scene's shown (issue 64): chosen for one scene, it stayed
/// for every other scene until restart while their inspectors said `auto`.
#[test]
fn the_toolbar_solver_stays_with_the_scene_it_was_chosen_for() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    open_at_step_0(&mut h, "stack of boxes");
    let solver =
        |h: &Harness<'_, RoboSimApp>| h.state().sim().unwrap().world.settings.contact_solver;
    assert_eq!(solver(&h), pe::ContactSolver::Auto);
    h.get_by_label_contains("The contact solver: auto").click();
    h.run_steps(2);
    h.get_by_label("exact").click();
    h.run_steps(2);
    assert_eq!(solver(&h), pe::ContactSolver::Exact);
    // Reset keeps it for this scene.
    click(&mut h, "Reset");
    assert_eq!(solver(&h), pe::ContactSolver::Exact);
    // Another scene starts from its own (the default: auto).
    open_at_step_0(&mut h, "walker");
    assert_eq!(solver(&h), pe::ContactSolver::Auto);
}

/// Gravity, friction and the step change while a scene runs, without starting it again
/// (issue 64: any edit reset the run to step 0); other edits build it again at step 0.
#[test]
fn a_running_scene_takes_up_gravity_and_friction_as_it_runs() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    h.get_by_label("stack of boxes").click();
    h.run_steps(2);
    click(&mut h, "Play");
    h.run_steps(20);
    let before = h.state().sim().unwrap().step_count();
    assert!(before > 5, "{before} steps");
    type_into(&mut h, "gravitation", "50");
    type_into(&mut h, "friction μ", "0.2");
    let sim = h.state().sim().unwrap();
    assert!(
        sim.step_count() >= before,
        "the run went on: {}",
        sim.step_count()
    );
    assert_eq!(sim.world.gravity.y, 50.0);
    assert_eq!(sim.world.friction, 0.2);
    assert!(h.state().is_running());
    // Reset starts the edited scene again, with the new gravity.
    click(&mut h, "Pause");
    click(&mut h, "Reset");
    let sim = h.state().sim().unwrap();
    assert_eq!((sim.step_count(), sim.world.gravity.y), (0, 50.0));
}

/// Scrubbing back holds still under a held pointer (issue 64): each move dropped the run
/// after the step shown, the slider's range shrank under the pointer, and a 5-point drag
/// drifted from 7.2 s to 2.2 s. The run after the step shown goes only when it goes on.
#[test]
fn the_back_slider_holds_the_step_under_a_still_pointer() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    h.get_by_label("stack of boxes").click();
    h.run_steps(2);
    click(&mut h, "Play");
    h.state_mut().set_speed(8.0);
    h.run_steps(120);
    click(&mut h, "Pause");
    let slider = h.get_by_label("back").rect();
    let newest = h.state().sim().unwrap().step_count();
    // Press at the slider's right end, move 20 points left, and hold for 30 frames.
    let start = egui::pos2(slider.right() - 2.0, slider.center().y);
    let end = start - egui::vec2(20.0, 0.0);
    press_and_move(&mut h, start, end, 5, Modifiers::NONE);
    let shown = h.state().sim().unwrap().step_count();
    assert!(shown < newest, "scrubbed back from {newest} to {shown}");
    for _ in 0..30 {
        h.event(Event::PointerMoved(end));
        h.run_steps(1);
        assert_eq!(h.state().sim().unwrap().step_count(), shown, "held still");
    }
    release(&mut h, end, Modifiers::NONE);
    assert_eq!(h.state().sim().unwrap().step_count(), shown);
    // Going on from there drops what came after it.
    click(&mut h, "Step");
    assert_eq!(h.state().sim().unwrap().step_count(), shown + 1);
}

/// Follow follows what moves: with a static body selected (terrain just drawn), the view
/// follows the moving bodies, not the terrain (issue 64).
#[test]
fn follow_with_terrain_selected_follows_the_moving_robot() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    open_at_step_0(&mut h, "car on terrain");
    // A point in view on a static body, to click: a grid over the canvas searched.
    let terrain = {
        let app = h.state();
        let sim = app.sim().unwrap();
        let (rect, camera) = (app.canvas_rect(), app.camera());
        let inside = |p: pe::Vec2| {
            sim.world.bodies().any(|(_, b)| {
                let v: Vec<pe::Vec2> = b.world_vertices().collect();
                b.is_static()
                    && (0..v.len()).all(|k| {
                        let (a, c) = (v[k], v[(k + 1) % v.len()]);
                        (c - a).perp(&(p - a)) >= 0.0
                    })
            })
        };
        (1..20)
            .flat_map(|i| (1..20).map(move |j| (i, j)))
            .map(|(i, j)| {
                let screen = rect.min + rect.size() * egui::vec2(i as f32, j as f32) / 20.0;
                camera.to_world(rect, screen)
            })
            .find(|&p| inside(p))
            .expect("a static body in view")
    };
    click_world(&mut h, terrain.x, terrain.y, Modifiers::NONE);
    let followed = h.state().followed().expect("the terrain is selected");
    assert!(
        h.state()
            .sim()
            .unwrap()
            .world
            .body(h.state().sim().unwrap().bodies[followed].handle)
            .unwrap()
            .is_static()
    );
    click(&mut h, "Play");
    h.state_mut().set_speed(4.0);
    // The view eases towards what it follows; the car drives right, so the view keeps
    // moving right (the terrain it followed before stands still).
    h.run_steps(5);
    let halfway = h.state().camera().centre.x;
    h.run_steps(5);
    assert!(h.state().is_running());
    let moved = h.state().camera().centre.x - halfway;
    let app = h.state();
    let sim = app.sim().unwrap();
    let chassis = sim
        .bodies
        .iter()
        .find(|b| b.id.ends_with("/chassis"))
        .unwrap();
    let car = sim.world.body(chassis.handle).unwrap().centroid();
    let view = app.camera().centre;
    // Followed, the terrain drew the view down to its own centre (51 below the car, and
    // 98 right in those frames, against 183).
    assert!(
        moved > 140.0 && (view.y - car.y).abs() < 25.0,
        "the view moved {moved:.0} right in 5 frames, to {view:?}; the car is at {car:?}"
    );
}

/// F1 opens the shortcut sheet and closes it again, as Esc does; Help has the user guide
/// The body editor's view holds while an outline is drawn (issue 64: it refitted when the
/// A robot's preview runs at the step of the scenes that use it, the step its motors'
/// speeds are shown at; a body alone does not run (issue 64).
#[test]
fn a_robot_previews_at_its_scenes_step_and_a_body_alone_does_not_run() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    let model = h.state().model().clone();
    let (scene_step, robot) = model
        .scenes
        .iter()
        .find_map(|s| Some((s.timestep?, s.robots.first()?.source.clone())))
        .expect("a scene with a step of its own and a robot");
    h.state_mut().select(Selection::Robot(robot.clone()));
    h.run_steps(2);
    assert_eq!(h.state().sim().unwrap().dt, scene_step, "robot {robot}");
    h.state_mut()
        .select(Selection::Body(model.bodies[0].name.clone()));
    h.run_steps(2);
    h.key_press(Key::Space);
    h.run_steps(3);
    assert!(!h.state().is_running());
    assert!(
        h.state().status().contains("nothing to run"),
        "{}",
        h.state().status()
    );
}

/// An edit a running scene cannot take up as it runs asks before it starts the run again
/// at step 0 (issue 64); Cancel leaves the run and the model as they were.
#[test]
fn an_edit_that_must_restart_a_run_asks_first() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    h.get_by_label("stack of boxes").click();
    h.run_steps(2);
    click(&mut h, "Play");
    h.run_steps(10);
    click(&mut h, "Pause");
    let before = h.state().model().clone();
    let steps = h.state().sim().unwrap().step_count();
    assert!(steps > 0);
    // The scene's solver is not one a run takes up as it goes.
    h.get_by_label_contains("This scene's own contact solver")
        .click();
    h.run_steps(2);
    h.get_by_label("exact").click();
    h.run_steps(4); // the question's window is laid out in a frame of its own first
    assert!(h.query_by_label("Edit and restart").is_some(), "asked");
    click(&mut h, "Cancel");
    assert_eq!(*h.state().model(), before, "nothing changed");
    assert_eq!(
        h.state().sim().unwrap().step_count(),
        steps,
        "the run is as it was"
    );
    // Asked again and confirmed: made, and the scene is at step 0.
    h.get_by_label_contains("This scene's own contact solver")
        .click();
    h.run_steps(2);
    h.get_by_label("exact").click();
    h.run_steps(4);
    click(&mut h, "Edit and restart");
    let scene = h.state().model().scene("stack of boxes").unwrap().clone();
    assert_eq!(scene.solver.as_deref(), Some("exact"));
    assert_eq!(h.state().sim().unwrap().step_count(), 0);
}

/// A motor bound to keys (issue 65) runs while its key is held and the scene runs: the
/// keyboard car drives right on Right and stays put without it; the shortcut sheet
/// lists the keys.
#[test]
fn held_arrow_keys_drive_the_keyboard_car() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    open_at_step_0(&mut h, "drive with the arrow keys");
    let chassis_x = |h: &Harness<'_, RoboSimApp>| {
        let sim = h.state().sim().unwrap();
        let b = sim
            .bodies
            .iter()
            .find(|b| b.id.ends_with("/chassis"))
            .unwrap();
        sim.world.body(b.handle).unwrap().position.x
    };
    click(&mut h, "Play");
    for _ in 0..30 {
        h.run_steps(1);
    }
    let start = chassis_x(&h);
    let key = |pressed| Event::Key {
        key: Key::ArrowRight,
        physical_key: None,
        pressed,
        repeat: false,
        modifiers: egui::Modifiers::NONE,
    };
    h.event(key(true));
    for _ in 0..90 {
        h.run_steps(1);
    }
    h.event(key(false));
    h.run_steps(1);
    let driven = chassis_x(&h) - start;
    assert!(driven > 30.0, "Right held: drove {driven}");
    h.key_press(Key::F1);
    h.run_steps(2);
    assert_eq!(
        h.query_all_by_label("Left / Right").count(),
        2,
        "both motors listed"
    );
}
