//! The `robosim` command line: the editor by default, `run` and `check` headless.
//! Every failure is one line on stderr and exit code 2.

use crate::animation;
use crate::db::{Database, Problem, one_line};
use crate::sim::Simulation;
use crate::sim::trace::Record;
use clap::{Parser, Subcommand, ValueEnum};
use pe::ContactSolver;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Debug, Parser)]
#[command(
    name = "robosim",
    version,
    about = "Design 2D robots from rigid polygons and watch them move"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// The database folder the editor opens (default: the embedded one from data/).
    #[arg(long, global = false)]
    pub db: Option<PathBuf>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate a scene headless and write a trace.
    Run(RunArgs),
    /// Check a database and print every problem; exit 1 if any is an error.
    Check {
        /// The database folder (bodies.xml, robots.xml, scenes.xml).
        #[arg(long)]
        db: PathBuf,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    Jsonl,
    Csv,
}

#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The database folder.
    #[arg(long)]
    pub db: PathBuf,
    /// The scene's name.
    #[arg(long)]
    pub scene: String,
    /// How many steps to simulate.
    #[arg(long, default_value_t = 1000)]
    pub steps: u64,
    /// The step in seconds (default: the scene's `timestep`, else 0.05).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_step)]
    pub dt: Option<f64>,
    /// The contact solver: auto, exact, soft, thesis or sequential (default: the scene's,
    /// else auto).
    #[arg(long, value_parser = parse_solver)]
    pub solver: Option<ContactSolver>,
    /// Let bodies at rest sleep (skipped until something wakes them): faster, and the
    /// trace shows them exactly still.
    #[arg(long)]
    pub sleep: bool,
    /// Write a record every K steps (and at step 0 and the last step).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    pub every: u64,
    /// The trace format (default: csv if --out ends in .csv, else jsonl).
    #[arg(long, value_enum)]
    pub format: Option<Format>,
    /// Write the trace to this file instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also write the run as an animated GIF (640 × 480, the whole run in view) to this
    /// file; with --gif and no --out, no trace is written.
    #[arg(long, value_name = "FILE")]
    pub gif: Option<PathBuf>,
    /// Steps between the GIF's frames (default: the whole number of steps nearest 1/25 s
    /// of simulated time).
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u64).range(1..))]
    pub gif_every: Option<u64>,
}

/// A step in seconds: a finite number > 0 (its range is the scene's to check).
fn parse_step(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(dt) if dt.is_finite() && dt > 0.0 => Ok(dt),
        Ok(dt) => Err(format!(
            "{} is not a step: a number of seconds > 0",
            crate::db::write::number(dt)
        )),
        Err(_) => Err(format!("\"{}\" is not a number", crate::db::clip(text))),
    }
}

fn parse_solver(name: &str) -> Result<ContactSolver, String> {
    // As a file's `solver=" soft "` is read: the spaces around a name are not part of it.
    ContactSolver::from_name(name.trim()).ok_or_else(|| {
        let names: Vec<_> = ContactSolver::ALL.iter().map(|s| s.name()).collect();
        format!("unknown solver \"{name}\" (one of {})", names.join(", "))
    })
}

/// What opening the editor says in a build without the `app` feature.
pub const NO_EDITOR: &str =
    "robosim was built without the editor (feature `app`); use `robosim run` / `robosim check`";

/// A failure to report: one line, exit code 2.
pub struct Failure(pub String);

/// Standard output, where a report or a trace goes. A write that fails ends the command
/// with one line and exit code 2 (a full disk, a closed descriptor); a reader that went
/// away (`robosim check | head -1`) ends it quietly, with exit code 0.
enum Written {
    Failed(Failure),
    ReaderGone,
}

impl Written {
    fn of(error: std::io::Error, what: &str) -> Self {
        if error.kind() == std::io::ErrorKind::BrokenPipe {
            Written::ReaderGone
        } else {
            Written::Failed(Failure(format!("cannot write {what}: {error}")))
        }
    }

    /// The command's outcome once output could not be written.
    fn outcome(self) -> Result<ExitCode, Failure> {
        match self {
            Written::Failed(failure) => Err(failure),
            Written::ReaderGone => Ok(ExitCode::SUCCESS),
        }
    }
}

/// Standard output as a file. Rust's own `stdout()` reports a closed descriptor
/// (`robosim run ... >&-`) as written, and the trace would vanish with exit code 0; a
/// file on descriptor 1 reports it.
fn standard_output() -> Box<dyn Write> {
    #[cfg(unix)]
    {
        use std::os::fd::FromRawFd;
        /// Descriptor 1, borrowed: written to, never closed.
        struct Descriptor1(std::mem::ManuallyDrop<std::fs::File>);
        impl Write for Descriptor1 {
            fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
                self.0.write(bytes)
            }
            fn flush(&mut self) -> std::io::Result<()> {
                self.0.flush()
            }
        }
        // SAFETY: descriptor 1 is the process's standard output, ours to write; it is
        // wrapped so that dropping the file does not close it.
        let file = unsafe { std::fs::File::from_raw_fd(1) };
        Box::new(Descriptor1(std::mem::ManuallyDrop::new(file)))
    }
    #[cfg(not(unix))]
    {
        Box::new(std::io::stdout())
    }
}

/// Whether standard output was closed when the process started (`>&-`), as the binary
/// noted before Rust's runtime put /dev/null in its place (`note_standard_output`).
static STANDARD_OUTPUT_CLOSED: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// Notes, before `main` (the runtime then opens /dev/null on a closed descriptor 1, and
/// writes vanish there without an error), whether standard output is closed. A /dev/null
/// opened by the caller (`> /dev/null`, `1<>/dev/null`, Python's `DEVNULL`) is open.
pub fn note_standard_output(closed: bool) {
    STANDARD_OUTPUT_CLOSED.store(closed, std::sync::atomic::Ordering::Relaxed);
}

fn standard_output_was_closed() -> bool {
    STANDARD_OUTPUT_CLOSED.load(std::sync::atomic::Ordering::Relaxed)
}

/// clap's message for bad arguments as one line: what is wrong and the arguments it names
/// (its usage lines and hints left out).
fn argument_error(rendered: &str) -> String {
    let lines: Vec<&str> = rendered
        .lines()
        .map(str::trim)
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .filter(|l| !l.is_empty() && !l.starts_with("tip:"))
        .collect();
    let line = lines.join(" ");
    let line = line.trim_start_matches("error: ").to_string();
    if line.is_empty() {
        "bad arguments".to_string()
    } else {
        line
    }
}

/// Runs the CLI with `args`; `open_editor` is called when no subcommand is given.
pub fn main(
    args: impl IntoIterator<Item = std::ffi::OsString>,
    open_editor: impl FnOnce(Option<PathBuf>) -> Result<(), String>,
) -> ExitCode {
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help, --version
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            let line = argument_error(&e.render().to_string());
            let _ = writeln!(std::io::stderr(), "robosim: {}", one_line(line));
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        None => open_editor(cli.db)
            .map(|()| ExitCode::SUCCESS)
            .map_err(Failure),
        Some(Command::Check { db }) => check(&db),
        Some(Command::Run(args)) => run(&args),
    };
    match result {
        Ok(code) => code,
        Err(Failure(message)) => {
            // Nowhere left to say it if standard error is gone too: the exit code says it.
            let _ = writeln!(std::io::stderr(), "robosim: {}", one_line(message));
            ExitCode::from(2)
        }
    }
}

fn require_dir(db: &Path) -> Result<(), Failure> {
    if db.is_dir() {
        Ok(())
    } else {
        Err(Failure(format!("{}: not a database folder", db.display())))
    }
}

/// `robosim check`: every problem, one per line; exit 1 on errors.
pub fn check(db: &Path) -> Result<ExitCode, Failure> {
    require_dir(db)?;
    let (database, problems) = Database::load(db);
    let errors = problems.iter().filter(|p| p.is_error()).count();
    let warnings = problems.len() - errors;
    let m = &database.model;
    if standard_output_was_closed() {
        return Err(Failure(
            "standard output is closed: nowhere to write the report".into(),
        ));
    }
    let mut out = std::io::BufWriter::new(standard_output());
    let report = (|| {
        for p in &problems {
            writeln!(out, "{p}")?;
        }
        writeln!(
            out,
            "{}: {} bodies, {} robots, {} scenes; {errors} errors, {warnings} warnings",
            db.display(),
            m.bodies.len(),
            m.robots.len(),
            m.scenes.len()
        )?;
        out.flush()
    })();
    if let Err(e) = report {
        return Written::of(e, "the report to standard output").outcome();
    }
    Ok(if errors > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

/// `robosim run`.
pub fn run(args: &RunArgs) -> Result<ExitCode, Failure> {
    require_dir(&args.db)?;
    let (database, problems) = Database::load(&args.db);
    // Only what the scene uses must be right: the rest of the database is reported in
    // one line and does not stop the run.
    // (A scene that did not load may be among the records a broken file lost: then every
    // error is the scene's business.)
    let own_problems;
    let scene_problems = if database.model.scene(&args.scene).is_some() {
        own_problems = database.scene_problems(&args.scene);
        &own_problems
    } else {
        &problems
    };
    let errors: Vec<&Problem> = scene_problems.iter().filter(|p| p.is_error()).collect();
    if let Some(first) = errors.first() {
        let more = if errors.len() > 1 {
            format!(" (and {} more: see robosim check)", errors.len() - 1)
        } else {
            String::new()
        };
        return Err(Failure(format!("{first}{more}")));
    }
    refuse_unsafe_outputs(args)?;
    let mut sim = Simulation::new(&database.model, &args.scene, args.dt, args.solver)
        .map_err(|e| Failure(format!("{}: {e}", args.db.display())))?;
    // Said once the run is sure to start, so that a failure stays one line.
    let errors_elsewhere = problems.iter().filter(|p| p.is_error()).count();
    if errors_elsewhere > 0 {
        let _ = writeln!(
            std::io::stderr(),
            "robosim: warning: {}: {errors_elsewhere} errors in records scene \"{}\" does not use (see robosim check)",
            args.db.display(),
            crate::db::clip(&args.scene)
        );
    }
    sim.world.settings.sleeping = args.sleep;
    let format = args.format.unwrap_or(match &args.out {
        Some(p) if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv")) => Format::Csv,
        _ => Format::Jsonl,
    });
    let sink: Box<dyn Write> = match &args.out {
        Some(path) => Box::new(
            std::fs::File::create(path)
                .map_err(|e| Failure(format!("{}: cannot write: {e}", path.display())))?,
        ),
        // A GIF alone was asked for.
        None if args.gif.is_some() => Box::new(std::io::sink()),
        None if standard_output_was_closed() => {
            return Err(Failure(
                "standard output is closed: nowhere to write the trace (use --out FILE)".into(),
            ));
        }
        None => standard_output(),
    };
    let destination = match &args.out {
        Some(path) => path.display().to_string(),
        None => "the trace to standard output".to_string(),
    };
    let mut out = std::io::BufWriter::new(sink);
    let progress = if args.steps >= 5_000 {
        indicatif::ProgressBar::new(args.steps) // drawn only when stderr is a terminal
    } else {
        indicatif::ProgressBar::hidden()
    };
    let written = |e: std::io::Error| Written::of(e, &destination);
    let mut header_written = false;
    let mut emit = |sim: &Simulation, out: &mut dyn Write| -> Result<(), std::io::Error> {
        let record = Record::of(sim);
        match format {
            Format::Jsonl => writeln!(out, "{}", record.to_json_line()),
            Format::Csv => {
                let mut w = csv::WriterBuilder::new()
                    .has_headers(false)
                    .from_writer(out);
                if !header_written {
                    w.write_record(record.csv_header())?;
                    header_written = true;
                }
                w.write_record(record.csv_row())?;
                w.flush()
            }
        }
    };
    if let Err(e) = emit(&sim, &mut out) {
        return written(e).outcome();
    }
    let mut movie = args.gif.as_ref().map(|_| {
        let every = args
            .gif_every
            .unwrap_or_else(|| animation::steps_per_frame(sim.dt))
            .max(animation::every_for_at_most_max_frames(args.steps));
        (animation::Recording::default(), every)
    });
    if let Some((recording, _)) = movie.as_mut() {
        recording.capture(&sim);
    }
    for _ in 0..args.steps {
        let stepped = sim.try_step();
        let step = sim.step_count();
        if let Err(reason) = stepped {
            let _ = out.flush();
            let failed = format!(
                "scene \"{}\": step {step}: {reason}",
                crate::db::clip(&args.scene)
            );
            // What was simulated is still worth seeing: the GIF ends at the last good step.
            let gif_note = match (movie, &args.gif) {
                (Some((recording, _)), Some(path)) => match write_gif(&recording, path) {
                    Ok(()) => format!(" ({} shows the steps before)", path.display()),
                    Err(Failure(why)) => format!(" (and {why})"),
                },
                _ => String::new(),
            };
            return Err(Failure(failed + &gif_note));
        }
        if (step % args.every == 0 || step == args.steps)
            && let Err(e) = emit(&sim, &mut out)
        {
            return written(e).outcome();
        }
        if let Some((recording, every)) = movie.as_mut()
            && step.is_multiple_of(*every)
        {
            recording.capture(&sim);
        }
        progress.inc(1);
    }
    progress.finish_and_clear();
    if let Err(e) = out.flush() {
        return written(e).outcome();
    }
    if let (Some((recording, _)), Some(path)) = (movie, &args.gif) {
        write_gif(&recording, path)?;
    }
    Ok(ExitCode::SUCCESS)
}

fn write_gif(recording: &animation::Recording, path: &Path) -> Result<(), Failure> {
    let gif = recording
        .to_gif(animation::WIDTH, animation::HEIGHT)
        .map_err(Failure)?;
    animation::write_atomically(path, &gif).map_err(Failure)
}

/// Refuses, before anything is simulated, outputs that would destroy something or could
/// not be written at the end: the database's own files (as they are or would be, through
/// links and hard links), the trace and the GIF in one file, a GIF into a folder.
fn refuse_unsafe_outputs(args: &RunArgs) -> Result<(), Failure> {
    let outputs = [("--out", &args.out), ("--gif", &args.gif)];
    for (flag, path) in outputs.iter().filter_map(|(f, p)| Some((*f, p.as_ref()?))) {
        refuse_to_overwrite_the_database(flag, path, &args.db)?;
    }
    if let (Some(out), Some(gif)) = (&args.out, &args.gif)
        && crate::paths::same_file(out, gif)
    {
        return Err(Failure(format!(
            "{}: --out and --gif name the same file; choose two",
            gif.display()
        )));
    }
    if let Some(gif) = &args.gif {
        require_folder_of(gif)?;
        if gif.is_dir() {
            return Err(Failure(format!(
                "cannot write {}: it is a folder; --gif takes a file name",
                gif.display()
            )));
        }
    }
    Ok(())
}

/// Refuses a file whose folder does not exist, before the run rather than after it.
fn require_folder_of(file: &Path) -> Result<(), Failure> {
    match file.parent() {
        Some(folder) if !folder.as_os_str().is_empty() && !folder.is_dir() => {
            Err(Failure(format!(
                "cannot write {}: no folder {}",
                file.display(),
                folder.display()
            )))
        }
        _ => Ok(()),
    }
}

/// Refuses an output (`flag`'s file) that is one of the database's own files, or would
/// be one (a collection the database does not have yet), or the folder.
fn refuse_to_overwrite_the_database(flag: &str, out: &Path, db: &Path) -> Result<(), Failure> {
    let files = crate::db::FileKind::ALL.map(|k| db.join(k.file_name()));
    let same = crate::paths::same_file;
    if same(out, db) || files.iter().any(|f| same(out, f)) {
        return Err(Failure(format!(
            "{}: {flag} would overwrite the database being run; choose another file",
            out.display()
        )));
    }
    Ok(())
}
