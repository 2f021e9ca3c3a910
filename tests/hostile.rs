//! Hostile input, as a corpus: each folder of tests/hostile/ is a database, and its
//! `expect` file lists commands with the exact exit code, standard output and standard
//! error they must give. Faults no file can hold (a FIFO, a device, a full disk, a closed
//! pipe or descriptor) are tests of their own below.
//!
//! An `expect` file is blocks separated by blank lines: `# comment`, `args: ...` (split
//! at spaces outside double quotes; `{db}` is the folder, `\n` and `\e` a line break and
//! an escape character), `exit: N`, and every line of output as `out: ...` or `err: ...`.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const ROBOSIM: &str = env!("CARGO_BIN_EXE_robosim");

struct Case {
    args: Vec<String>,
    exit: i32,
    out: Vec<String>,
    err: Vec<String>,
}

/// Splits at spaces outside double quotes, and unescapes `\n` and `\e`.
fn split_args(line: &str) -> Vec<String> {
    let mut args = Vec::new();
    let (mut current, mut quoted, mut any) = (String::new(), false, false);
    for c in line.chars() {
        match c {
            '"' => (quoted, any) = (!quoted, true),
            ' ' if !quoted => {
                if any || !current.is_empty() {
                    args.push(std::mem::take(&mut current));
                }
                any = false;
            }
            c => current.push(c),
        }
    }
    if any || !current.is_empty() {
        args.push(current);
    }
    args.into_iter()
        .map(|a| a.replace("\\n", "\n").replace("\\e", "\u{1b}"))
        .collect()
}

fn cases(expect: &str, db: &str) -> Vec<Case> {
    let mut cases = Vec::new();
    for block in expect.split("\n\n").filter(|b| !b.trim().is_empty()) {
        let mut case = Case {
            args: Vec::new(),
            exit: -1,
            out: Vec::new(),
            err: Vec::new(),
        };
        for line in block.lines() {
            let line = line.replace("{db}", db);
            if let Some(args) = line.strip_prefix("args: ") {
                case.args = split_args(args);
            } else if let Some(code) = line.strip_prefix("exit: ") {
                case.exit = code.parse().expect("an exit code");
            } else if let Some(out) = line.strip_prefix("out: ") {
                case.out.push(out.to_string());
            } else if let Some(err) = line.strip_prefix("err: ") {
                case.err.push(err.to_string());
            } else {
                assert!(line.starts_with('#'), "an unknown line: {line}");
            }
        }
        cases.push(case);
    }
    cases
}

fn lines(bytes: &[u8]) -> Vec<String> {
    String::from_utf8_lossy(bytes)
        .lines()
        .map(str::to_string)
        .collect()
}

#[test]
fn every_hostile_database_gives_its_exact_messages_and_exit_code() {
    let root = Path::new("tests/hostile");
    let mut folders: Vec<PathBuf> = std::fs::read_dir(root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    folders.sort();
    assert!(folders.len() >= 10, "the corpus is there: {folders:?}");
    let mut checked = 0;
    for folder in folders {
        let expect = std::fs::read_to_string(folder.join("expect"))
            .unwrap_or_else(|e| panic!("{}: {e}", folder.display()));
        let db = folder.display().to_string();
        for case in cases(&expect, &db) {
            let output = Command::new(ROBOSIM).args(&case.args).output().unwrap();
            let what = format!("{}: robosim {:?}", folder.display(), case.args);
            assert_eq!(output.status.code(), Some(case.exit), "{what}: exit code");
            assert_eq!(lines(&output.stdout), case.out, "{what}: standard output");
            assert_eq!(lines(&output.stderr), case.err, "{what}: standard error");
            checked += 1;
        }
    }
    assert!(checked >= 15, "{checked} commands checked");
}

/// A database folder with the default database's files.
fn copy_of_data() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for name in ["bodies.xml", "robots.xml", "scenes.xml"] {
        std::fs::copy(Path::new("data").join(name), dir.path().join(name)).unwrap();
    }
    dir
}

#[cfg(unix)]
#[test]
fn a_fifo_or_a_device_in_place_of_a_file_is_refused_without_waiting_or_reading_for_ever() {
    let dir = copy_of_data();
    let bodies = dir.path().join("bodies.xml");
    std::fs::remove_file(&bodies).unwrap();
    let made = Command::new("mkfifo").arg(&bodies).status().unwrap();
    assert!(made.success());
    let output = Command::new(ROBOSIM)
        .args(["check", "--db"])
        .arg(dir.path())
        .output()
        .unwrap();
    let out = lines(&output.stdout);
    assert_eq!(
        out[0],
        format!(
            "{}: error: file: cannot read: not a regular file (a folder, a FIFO or a device)",
            bodies.display()
        )
    );
    std::fs::remove_file(&bodies).unwrap();
    std::os::unix::fs::symlink("/dev/zero", &bodies).unwrap();
    let output = Command::new(ROBOSIM)
        .args(["check", "--db"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        lines(&output.stdout)[0]
            .ends_with("cannot read: not a regular file (a folder, a FIFO or a device)")
    );
}

#[cfg(unix)]
#[test]
fn output_that_cannot_be_written_ends_in_one_line_and_a_closed_pipe_quietly() {
    let full = || std::fs::File::create("/dev/full").unwrap();
    for args in [
        vec!["check", "--db", "data"],
        vec!["run", "--db", "data", "--scene", "walker", "--steps", "100"],
    ] {
        let output = Command::new(ROBOSIM)
            .args(&args)
            .stdout(full())
            .output()
            .unwrap();
        assert_eq!(output.status.code(), Some(2), "{args:?} > /dev/full");
        let err = lines(&output.stderr);
        assert_eq!(err.len(), 1, "{err:?}");
        assert!(err[0].contains("No space left on device"), "{err:?}");

        // A reader that goes away at once.
        let mut child = Command::new(ROBOSIM)
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let output = child.wait_with_output().unwrap();
        assert_eq!(output.status.code(), Some(0), "{args:?} | (closed)");
        assert!(output.stderr.is_empty(), "{:?}", lines(&output.stderr));
    }
}

#[cfg(unix)]
#[test]
fn a_closed_standard_output_is_an_error_not_a_trace_lost_in_silence() {
    use std::os::unix::process::CommandExt;
    let mut command = Command::new(ROBOSIM);
    command.args(["run", "--db", "data", "--scene", "walker", "--steps", "3"]);
    // SAFETY: closing descriptor 1 in the child before it runs robosim (`>&-`).
    unsafe {
        command.pre_exec(|| {
            libc::close(1);
            Ok(())
        });
    }
    let output = command.stderr(Stdio::piped()).output().unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert_eq!(
        lines(&output.stderr),
        ["robosim: standard output is closed: nowhere to write the trace (use --out FILE)"]
    );
}

/// `robosim run --db DB --scene walker --steps 2` with `extra` arguments.
fn run_walker(db: &Path, extra: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new(ROBOSIM)
        .args(["run", "--scene", "walker", "--steps", "2", "--db"])
        .arg(db)
        .args(extra)
        .output()
        .unwrap()
}

#[cfg(unix)]
#[test]
fn an_output_that_is_a_database_file_by_another_name_is_refused() {
    let dir = copy_of_data();
    let scenes = dir.path().join("scenes.xml");
    let before = std::fs::read(&scenes).unwrap();
    let elsewhere = tempfile::tempdir().unwrap();

    // A hard link: another path, the same file.
    let hard = elsewhere.path().join("trace.jsonl");
    std::fs::hard_link(&scenes, &hard).unwrap();
    let output = run_walker(dir.path(), &["--out".as_ref(), hard.as_os_str()]);
    assert_eq!(output.status.code(), Some(2), "{:?}", lines(&output.stderr));
    assert_eq!(
        lines(&output.stderr),
        [format!(
            "robosim: {}: --out would overwrite the database being run; choose another file",
            hard.display()
        )]
    );
    assert_eq!(std::fs::read(&scenes).unwrap(), before);

    // A file the database does not have yet (no robots.xml is an empty collection): the
    // trace written there would become the database's robots.
    let db = tempfile::tempdir().unwrap();
    let hostile = Path::new("tests/hostile/cli_arguments");
    std::fs::copy(hostile.join("bodies.xml"), db.path().join("bodies.xml")).unwrap();
    std::fs::write(
        db.path().join("scenes.xml"),
        r#"<scenes><scene name="s" gravitation="10"><body alias="b" source="box" x="0" y="0"/></scene></scenes>"#,
    )
    .unwrap();
    let robots = db.path().join("robots.xml");
    for flag in ["--out", "--gif"] {
        let output = Command::new(ROBOSIM)
            .args(["run", "--scene", "s", "--steps", "2", "--db"])
            .arg(db.path())
            .arg(flag)
            .arg(&robots)
            .output()
            .unwrap();
        assert_eq!(output.status.code(), Some(2), "{flag}");
        assert!(!robots.exists(), "{flag} wrote robots.xml");
    }
}

#[cfg(unix)]
#[test]
fn a_gif_is_written_through_a_symbolic_link_and_into_a_device() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("run.gif");
    let link = dir.path().join("link.gif");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let output = run_walker(Path::new("data"), &["--gif".as_ref(), link.as_os_str()]);
    assert!(output.status.success(), "{:?}", lines(&output.stderr));
    assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
    assert!(std::fs::read(&target).unwrap().starts_with(b"GIF89a"));

    // A link to a device is written through, never replaced by a file.
    let to_stdout = dir.path().join("stdout.gif");
    std::os::unix::fs::symlink("/dev/stdout", &to_stdout).unwrap();
    let output = run_walker(
        Path::new("data"),
        &["--gif".as_ref(), to_stdout.as_os_str()],
    );
    assert!(output.status.success(), "{:?}", lines(&output.stderr));
    assert!(output.stdout.starts_with(b"GIF89a"));
    assert!(std::fs::symlink_metadata(&to_stdout).unwrap().is_symlink());
}

#[cfg(unix)]
#[test]
fn standard_output_on_a_read_write_dev_null_is_open() {
    // What Python's `subprocess.DEVNULL` and a shell's `1<>/dev/null` give.
    let null = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open("/dev/null")
        .unwrap();
    for args in [
        vec!["check", "--db", "data"],
        vec!["run", "--db", "data", "--scene", "walker", "--steps", "3"],
    ] {
        let output = Command::new(ROBOSIM)
            .args(&args)
            .stdout(null.try_clone().unwrap())
            .output()
            .unwrap();
        assert_eq!(
            output.status.code(),
            Some(0),
            "{args:?}: {:?}",
            lines(&output.stderr)
        );
    }
}

#[cfg(unix)]
#[test]
fn a_database_file_linked_to_nothing_is_an_error_not_an_empty_collection() {
    let dir = copy_of_data();
    let bodies = dir.path().join("bodies.xml");
    std::fs::remove_file(&bodies).unwrap();
    std::os::unix::fs::symlink("gone.xml", &bodies).unwrap();
    let output = Command::new(ROBOSIM)
        .args(["check", "--db"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1));
    assert_eq!(
        lines(&output.stdout)[0],
        format!(
            "{}: error: file: cannot read: a symbolic link to gone.xml, which does not exist",
            bodies.display()
        )
    );
}
