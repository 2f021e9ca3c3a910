//! The `robosim` binary (issue 6): `run` and `check` as a user's script would call them.

use assert_cmd::Command;

fn robosim() -> Command {
    Command::cargo_bin("robosim").unwrap()
}

fn run(args: &[&str]) -> std::process::Output {
    robosim()
        .args(["run", "--db", "data"])
        .args(args)
        .output()
        .unwrap()
}

/// The JSON Lines records of a successful run.
fn json_records(out: std::process::Output) -> Vec<serde_json::Value> {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn run_writes_parseable_json_lines_at_0_every_k_and_the_last_step() {
    let out = run(&["--scene", "stack of boxes", "--steps", "10", "--every", "4"]);
    let records = json_records(out);
    let steps: Vec<u64> = records
        .iter()
        .map(|r| r["step"].as_u64().unwrap())
        .collect();
    assert_eq!(steps, [0, 4, 8, 10]);
    let r = &records[1];
    assert!((r["time"].as_f64().unwrap() - 4.0 / 60.0).abs() < 1e-15);
    let body = &r["bodies"][1];
    assert_eq!(body["id"], "box 1");
    for key in ["x", "y", "angle", "vx", "vy", "omega"] {
        assert!(body[key].is_f64(), "{key}");
    }
    assert!(r["energy"]["kinetic"].is_f64() && r["energy"]["potential"].is_f64());
    assert!(r["joints"].as_array().unwrap().is_empty());
}

#[test]
fn the_same_run_twice_is_byte_identical() {
    let args = [
        "--scene",
        "car on terrain",
        "--steps",
        "300",
        "--every",
        "7",
    ];
    let (a, b) = (run(&args), run(&args));
    assert!(a.status.success());
    assert!(!a.stdout.is_empty());
    assert_eq!(a.stdout, b.stdout);
}

#[test]
fn csv_has_a_header_and_one_row_per_record() {
    let out = run(&[
        "--scene",
        "double pendulum",
        "--steps",
        "5",
        "--format",
        "csv",
    ]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let mut rows = csv::Reader::from_reader(text.as_bytes());
    let header = rows.headers().unwrap().clone();
    assert_eq!(
        header.iter().take(4).collect::<Vec<_>>(),
        ["step", "time", "kinetic", "potential"]
    );
    assert!(header.iter().any(|h| h == "double pendulum#0/upper.omega"));
    assert!(
        header
            .iter()
            .any(|h| h == "double pendulum#0/upper-lower.gap")
    );
    let rows: Vec<_> = rows.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 6);
    assert!(rows.iter().all(|r| r.len() == header.len()));
}

#[test]
fn out_writes_a_file_and_dt_and_solver_apply() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("trace.jsonl");
    let out = run(&[
        "--scene",
        "stack of boxes",
        "--steps",
        "3",
        "--dt",
        "0.01",
        "--solver",
        "thesis",
        "--out",
    ])
    .status;
    assert!(!out.success(), "--out needs a value");
    let status = robosim()
        .args([
            "run",
            "--db",
            "data",
            "--scene",
            "stack of boxes",
            "--steps",
            "3",
            "--dt",
            "0.01",
        ])
        .args(["--solver", "thesis", "--out", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(status.status.success() && status.stdout.is_empty());
    let last: serde_json::Value = serde_json::from_str(
        std::fs::read_to_string(&path)
            .unwrap()
            .lines()
            .last()
            .unwrap(),
    )
    .unwrap();
    assert!((last["time"].as_f64().unwrap() - 0.03).abs() < 1e-15);
}

/// Every failure: exit code 2 and one line on stderr naming the problem.
#[test]
fn errors_are_one_line_and_exit_2() {
    let cases: [(&[&str], &str); 6] = [
        (
            &["run", "--db", "data", "--scene", "no such scene"],
            "no scene \"no such scene\"",
        ),
        (
            &["run", "--db", "no/such/dir", "--scene", "x"],
            "not a database folder",
        ),
        (
            &[
                "run", "--db", "data", "--scene", "walker", "--solver", "magic",
            ],
            "unknown solver",
        ),
        (
            &["run", "--db", "data", "--scene", "walker", "--dt", "5"],
            "outside",
        ),
        (
            &["run", "--db", "data", "--scene", "walker", "--every", "0"],
            "--every",
        ),
        (&["bogus"], "unrecognized subcommand"),
    ];
    for (args, says) in cases {
        let out = robosim().args(args).output().unwrap();
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"));
    }
}

#[test]
fn run_refuses_an_invalid_database() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bodies.xml"),
        "<bodies><body name=\"x\" density=\"oops\" cor=\"0\"/></bodies>",
    )
    .unwrap();
    let out = robosim()
        .args(["run", "--db", dir.path().to_str().unwrap(), "--scene", "s"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.contains("bodies.xml:1:") && stderr.contains("density=\"oops\" is not a number"),
        "{stderr}"
    );
}

#[test]
fn check_passes_the_default_database_and_fails_a_broken_one() {
    let out = robosim().args(["check", "--db", "data"]).output().unwrap();
    assert!(out.status.success());
    assert!(
        String::from_utf8(out.stdout)
            .unwrap()
            .contains("0 errors, 0 warnings")
    );
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        "tests/corpus/dangling_scenes.xml",
        dir.path().join("scenes.xml"),
    )
    .unwrap();
    let out = robosim()
        .args(["check", "--db", dir.path().to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(stdout.contains("scenes.xml:3:5: error: <robot> in scene \"lost\": source \"no such robot\" is not a robot"), "{stdout}");
}

#[test]
fn sleep_lets_the_stack_of_boxes_come_exactly_to_rest() {
    // The stack settles and the ball rolls to a stop; with --sleep the last records show
    // every body exactly still, and its pose the same in both.
    let out = run(&[
        "--scene",
        "stack of boxes",
        "--steps",
        "1200",
        "--every",
        "600",
        "--sleep",
    ]);
    let records = json_records(out);
    let (middle, last) = (&records[1], &records[2]);
    for (a, b) in middle["bodies"]
        .as_array()
        .unwrap()
        .iter()
        .zip(last["bodies"].as_array().unwrap())
    {
        for key in ["vx", "vy", "omega"] {
            assert_eq!(b[key].as_f64(), Some(0.0), "{} {key}", b["id"]);
        }
        for key in ["x", "y", "angle"] {
            assert_eq!(a[key], b[key], "{} {key}", b["id"]);
        }
    }
}

/// A headless build (`cargo test --no-default-features`): opening the editor says why it
/// cannot, in one line with exit code 2, while `check` still works.
#[cfg(not(feature = "app"))]
#[test]
fn without_the_app_feature_the_editor_is_refused_clearly() {
    for args in [&[][..], &["--db", "data"][..]] {
        let out = robosim().args(args).output().unwrap();
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(
            stderr.trim_end(),
            format!("robosim: {}", robosim::cli::NO_EDITOR),
            "{args:?}"
        );
    }
    let out = robosim().args(["check", "--db", "data"]).output().unwrap();
    assert!(out.status.success());
}

/// The frames of a GIF as RGBA pixels, with the picture's size.
fn gif_frames(path: &std::path::Path) -> (u16, u16, Vec<Vec<u8>>) {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options
        .read_info(std::fs::File::open(path).unwrap())
        .unwrap();
    let (w, h) = (decoder.width(), decoder.height());
    let mut frames = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert_eq!((frame.width, frame.height), (w, h), "whole frames");
        frames.push(frame.buffer.to_vec());
    }
    (w, h, frames)
}

#[test]
fn gif_writes_the_run_as_an_animation_without_a_trace() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("stack.gif");
    let out = run(&[
        "--scene",
        "stack of boxes",
        "--steps",
        "60",
        "--gif-every",
        "6",
        "--gif",
        path.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stdout.is_empty(), "no --out: the GIF alone");
    // Steps 0, 6, …, 60: 11 frames of 640 × 480.
    let (w, h, frames) = gif_frames(&path);
    assert_eq!((w, h, frames.len()), (640, 480, 11));
    // The ball falls: the first and last frames differ, while the stack stands.
    assert_ne!(frames[0], frames[10]);
    // The default: a frame every 1/25 s, two steps of 1/60 s.
    let out = run(&[
        "--scene",
        "stack of boxes",
        "--steps",
        "30",
        "--gif",
        path.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert_eq!(gif_frames(&path).2.len(), 16);
}

#[test]
fn a_gif_that_cannot_be_written_is_one_line_and_exit_2_and_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no such folder").join("x.gif");
    let out = run(&[
        "--scene",
        "stack of boxes",
        "--steps",
        "5",
        "--gif",
        missing.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("cannot write") && err.contains("x.gif"),
        "{err}"
    );
    // A folder, not a file, where the GIF should go: refused after the run, nothing left.
    let folder = dir.path().join("taken.gif");
    std::fs::create_dir(&folder).unwrap();
    let out = run(&[
        "--scene",
        "stack of boxes",
        "--steps",
        "5",
        "--gif",
        folder.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(String::from_utf8(out.stderr).unwrap().lines().count(), 1);
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "no temporary file left behind: {left:?}");
}

/// A name with an escape sequence and a carriage return (issue 63): the CSV stays valid
/// RFC 4180 and carries no control character, written as JSON writes them.
#[test]
fn csv_never_carries_a_control_character_from_a_name() {
    let db = tempfile::tempdir().unwrap();
    std::fs::copy(
        "tests/hostile/cli_arguments/bodies.xml",
        db.path().join("bodies.xml"),
    )
    .unwrap();
    std::fs::write(
        db.path().join("scenes.xml"),
        "<scenes><scene name=\"s\" gravitation=\"10\" friction=\"0.5\">\
         <body alias=\"red\u{1b}[31m&#13;x\" source=\"box\" x=\"0\" y=\"0\"/></scene></scenes>",
    )
    .unwrap();
    let out = robosim()
        .args([
            "run", "--scene", "s", "--steps", "2", "--format", "csv", "--db",
        ])
        .arg(db.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        !text.chars().any(|c| c.is_control() && c != '\n'),
        "{text:?}"
    );
    let header = text.lines().next().unwrap();
    assert!(header.contains("red\\u001b[31m\\u000dx.x"), "{header}");
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let widths: Vec<usize> = reader.records().map(|r| r.unwrap().len()).collect();
    assert_eq!(widths, [10, 10, 10]);
}
