//! The drawing tools: a box or a regular polygon dragged out on the canvas becomes a new
//! body definition placed where it was drawn, in a scene or a robot, as one undo step.

use super::{click, click_world, drag_world, harness, new_item, open_at_step_0, scratch_db};
use egui::{Key, Modifiers};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use robosim::app::{RoboSimApp, Selection};

fn undo(h: &mut Harness<'_, RoboSimApp>) {
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run_steps(2);
}

#[test]
fn a_box_dragged_into_a_scene_is_a_new_body_placed_there_and_one_undo_takes_both() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    open_at_step_0(&mut h, "stack of boxes");
    let before = h.state().model().clone();
    h.key_press(Key::B);
    h.run_steps(2);
    // From corner (600, 200) to (640, 230): a 40 × 30 box centred at (620, 215).
    drag_world(&mut h, (600.0, 200.0), (640.0, 230.0));
    let model = h.state().model().clone();
    assert_eq!(
        model.bodies.len(),
        before.bodies.len() + 1,
        "{}",
        h.state().status()
    );
    // "box 1" … "box 8" are the scene's aliases already: the first free name is "box 9".
    let body = model.body("box 9").expect("a body named box 9");
    assert_eq!(
        body.vertices,
        [[-20.0, -15.0], [20.0, -15.0], [20.0, 15.0], [-20.0, 15.0]]
    );
    assert_eq!((body.density, body.cor), (1.0, 0.2));
    let scene = model.scene("stack of boxes").unwrap();
    let placed = scene.bodies.last().unwrap();
    assert_eq!(
        (
            placed.alias.as_str(),
            placed.source.as_str(),
            placed.x,
            placed.y
        ),
        ("box 9", "box 9", 620.0, 215.0)
    );
    assert_eq!(
        scene.bodies.len(),
        before.scene("stack of boxes").unwrap().bodies.len() + 1
    );
    // It simulates where it was drawn, and is selected.
    let sim = h.state().sim().unwrap();
    let i = sim.bodies.iter().position(|b| b.id == "box 9").unwrap();
    let origin = sim.world.body(sim.bodies[i].handle).unwrap().origin();
    assert_eq!((origin.x, origin.y), (620.0, 215.0));
    assert_eq!(h.state().picked(), [i]);
    undo(&mut h);
    assert_eq!(
        *h.state().model(),
        before,
        "one undo removes the body and its placement"
    );

    // Static terrain: the checkbox beside the tool, density 0.
    click_label(&mut h, "static");
    drag_world(&mut h, (600.0, 200.0), (700.0, 210.0));
    let terrain = h.state().model().body("box 9").unwrap().clone();
    assert_eq!(terrain.density, 0.0);
    // A slip (a drag too thin to be a box) makes nothing and says why.
    let count = h.state().model().bodies.len();
    drag_world(&mut h, (600.0, 100.0), (650.0, 100.2));
    assert_eq!(h.state().model().bodies.len(), count);
    assert!(
        h.state().status().contains("drag further"),
        "{}",
        h.state().status()
    );
    // Esc goes back to selecting; the shortcut sheet lists the tools.
    h.key_press(Key::Escape);
    h.run_steps(2);
    drag_world(&mut h, (600.0, 100.0), (650.0, 150.0));
    assert_eq!(h.state().model().bodies.len(), count, "a drag now selects");
    h.key_press(Key::F1);
    h.run_steps(2);
    h.get_by_label_contains("Box tool");
}

fn click_label(h: &mut Harness<'_, RoboSimApp>, label: &str) {
    h.get_by_label(label).click();
    h.run_steps(2);
}

#[test]
fn a_polygon_dragged_into_a_robot_is_a_regular_body_of_that_radius_in_the_robot() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    h.get_by_label("housenka · 3 bodies, 2 joints").click();
    h.run_steps(2);
    assert!(matches!(h.state().selection(), Some(Selection::Robot(_))));
    let before = h.state().model().clone();
    click_label(&mut h, "Polygon");
    // From the centre (0, -60) out 25 to the right: a hexagon of circumradius 25.
    drag_world(&mut h, (0.0, -60.0), (25.0, -60.0));
    let model = h.state().model().clone();
    let body = model.body("hexagon 1").expect("a body named hexagon 1");
    assert_eq!(body.vertices.len(), 6);
    for v in &body.vertices {
        assert!((v[0].hypot(v[1]) - 25.0).abs() < 1e-3, "{v:?}");
    }
    assert_eq!(body.density, 1.0);
    let robot = model.robot("housenka").unwrap();
    let placed = &robot.bodies.last().unwrap().placement;
    assert_eq!(
        (placed.alias.as_str(), placed.x, placed.y),
        ("hexagon 1", 0.0, -60.0)
    );
    undo(&mut h);
    assert_eq!(*h.state().model(), before);
}

/// third vertex made a body, so the next click landed off target).
#[test]
fn the_body_editor_keeps_its_view_while_an_outline_is_drawn() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    new_item(&mut h, "body");
    click(&mut h, "Clear and draw");
    let mut views = Vec::new();
    for (x, y) in [(-35.0, -15.0), (35.0, -15.0), (35.0, 15.0), (-35.0, 15.0)] {
        click_world(&mut h, x, y, Modifiers::NONE);
        let camera = h.state().camera();
        views.push((camera.centre, camera.zoom));
    }
    let name = match h.state().selection() {
        Some(Selection::Body(name)) => name.clone(),
        other => panic!("{other:?}"),
    };
    assert_eq!(h.state().model().body(&name).unwrap().vertices.len(), 4);
    assert!(views.windows(2).all(|w| w[0] == w[1]), "{views:?}");
}

/// The body editor's shapes (issue 64's second hour): Regular polygon writes whole
/// thousandths with no `-0` (it wrote 7.3e-16 and showed -0.0), and a body cleared to
/// redraw is named once in the status bar (it read `body "b": b: body "b": …`).
#[test]
fn a_regular_polygon_is_written_clean_and_a_cleared_body_is_named_once() {
    let dir = scratch_db();
    let mut h = harness(dir.path());
    let name = super::new_body_selected(&mut h);
    click(&mut h, "Regular polygon");
    let vertices = h.state().model().body(&name).unwrap().vertices.clone();
    assert!(vertices.len() >= 3);
    for v in vertices.iter().flatten() {
        assert!(
            (v * 1000.0).fract() == 0.0 && !(*v == 0.0 && v.is_sign_negative()),
            "{vertices:?}"
        );
    }
    click(&mut h, "Clear and draw");
    let status = h.state().status().to_string();
    assert_eq!(status.matches(name.as_str()).count(), 1, "{status}");
}
