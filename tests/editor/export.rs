//! File → Export run as GIF…: the run shown, from step 0, as an animated GIF written on a
//! thread of its own.

use super::{open_at_step_0, scratch_db};
use egui::Key;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use robosim::app::RoboSimApp;
use robosim::app::files::{Answer, Scripted};

/// Runs frames until the status bar says `word`, for at most a minute.
fn wait_for_status(h: &mut Harness<'_, RoboSimApp>, word: &str) {
    let start = std::time::Instant::now();
    while !h.state().status().contains(word) {
        assert!(
            start.elapsed().as_secs() < 60,
            "still: {}",
            h.state().status()
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
    }
}

#[test]
fn the_run_shown_exports_as_a_gif_from_step_0_to_the_step_shown() {
    let dir = scratch_db();
    let gif = dir.path().join("run.gif");
    let unwritable = dir.path().join("no such folder").join("run.gif");
    let app = RoboSimApp::new(Some(dir.path().to_path_buf())).with_file_chooser(Box::new(
        Scripted::new([Answer::Chosen(gif.clone()), Answer::Chosen(unwritable)]),
    ));
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(move |_| app);
    h.run_steps(3);
    open_at_step_0(&mut h, "stack of boxes");
    // 30 steps of 1/60 s: the ball falls 25 px. Frames every 2 steps: 0, 2, …, 30.
    for _ in 0..30 {
        h.key_press(Key::S);
        h.run_steps(1);
    }
    assert_eq!(h.state().sim().unwrap().step_count(), 30);
    h.get_by_label("File").click();
    h.run_steps(2);
    h.get_by_label("Export run as GIF…").click();
    h.run_steps(2);
    wait_for_status(&mut h, "written");
    assert!(
        h.state().status().contains("16 frames"),
        "{}",
        h.state().status()
    );

    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options
        .read_info(std::fs::File::open(&gif).unwrap())
        .unwrap();
    assert_eq!((decoder.width(), decoder.height()), (640, 480));
    let mut frames = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        frames.push(frame.buffer.to_vec());
    }
    assert_eq!(frames.len(), 16);
    assert_ne!(frames[0], frames[15], "the ball moved");
    assert_eq!(
        h.state().sim().unwrap().step_count(),
        30,
        "the run shown is left as it was"
    );

    // A folder that does not exist: one line in the status bar, no panic.
    h.get_by_label("File").click();
    h.run_steps(2);
    h.get_by_label("Export run as GIF…").click();
    h.run_steps(2);
    wait_for_status(&mut h, "cannot write");
    assert_eq!(h.state().status().lines().count(), 1);
}
